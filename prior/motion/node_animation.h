// An animated node hierarchy sampled at a frame rate (what the glTF and FBX
// readers make of a file) and its conversion to mf::Motion: the boundary the
// scene formats share, beside BVH's (motion_bvh.h).
//
// The conversion works on world transforms, so anything above the armature
// (an armature object, a unit scale, the file's axes) is taken into account:
// - the joints are the nodes marked as joints; their parent is the nearest
//   joint above them. They must have exactly one top joint ("two roots"
//   otherwise).
// - Container roots, as in BVH (motion_bvh.h): while the top joint has exactly
//   one child joint and a joint at or below that child moves against its
//   parent (its translation is animated), the child becomes the root. So an
//   armature object or a "joint_Root" above the hips whose translation carries
//   the motion is composed into the hips.
// - The rest pose is the nodes' rest transforms. Rotations are made relative
//   to it: a joint's rotation is its world rotation times the inverse of its
//   world rest rotation (the rest pose has identity rotations, as in BVH), its
//   offset is its world rest position minus its parent's. Bone orientations
//   (a Blender bone along its Y axis) therefore do not show in the motion.
// - The root's positions are its world positions; other joints keep their rest
//   offsets (an animated translation below the root is not represented).
// - Scale is removed from world rotations (a uniformly scaled armature, as
//   FBX files from Blender have, gives metres).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <string>
#include <vector>

#include "prior/motion/motion.h"

namespace mf {

struct NodeTransform {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
};

/// A transform as a matrix (T * R * S) and back (a matrix without shear; a
/// mirror goes into the X scale).
Eigen::Affine3d to_affine(const NodeTransform& transform);
NodeTransform transform_from_affine(const Eigen::Affine3d& matrix);

/// Keys of one property of a node (translation, rotation or scale).
enum class KeyInterpolation { Step, Linear, CubicSpline };
struct KeyTrack {
  std::vector<double> times;   ///< seconds, strictly increasing; empty: not animated
  /// `width` numbers per key (3, or 4 for rotations: x, y, z, w); CubicSpline:
  /// three groups per key (in-tangent, value, out-tangent), as in glTF.
  std::vector<double> values;
  int width = 3;
  KeyInterpolation interpolation = KeyInterpolation::Linear;
  bool empty() const { return times.empty(); }
};

struct NodeTracks {
  KeyTrack translation, rotation, scale;
};

/// How a scene file's animation is read (glTF, FBX).
struct SceneReadOptions {
  std::string animation;    ///< the animation's name; "" = by index
  int animation_index = 0;  ///< used when `animation` is ""
  double fps = 0.0;         ///< the sampling rate; 0 = the keys' rate (fps_from_key_times)
};

struct NodeAnimation {
  std::vector<std::string> names;
  std::vector<int> parents;           ///< -1 for the scene's roots; every parent before its children
  std::vector<char> joints;           ///< 1 for the nodes of the armature (mark_joints)
  std::vector<NodeTransform> rest;    ///< local rest transforms (parent frame, file units)
  std::vector<NodeTracks> tracks;     ///< per node; a property without keys keeps its rest value
  /// File axes to motionfield's (Y up), a rotation; and metres per file unit.
  Eigen::Matrix3d to_y_up = Eigen::Matrix3d::Identity();
  double metres_per_unit = 1.0;
};

/// The most joints and the most joint-frames (joints times frames) a scene
/// file may give (the BVH reader's limits, prior/motion/bvh.h, in kind).
constexpr size_t kMaxSceneFileBytes = size_t{512} << 20;  ///< glTF and FBX files (and glTF's external buffers)
constexpr int kMaxSceneJoints = 1024;
constexpr long long kMaxSceneFrames = 10'000'000;
constexpr long long kMaxSceneJointFrames = 50'000'000;

/// The motion of the armature (see above), quaternion signs continuous in time,
/// sampled from the first key of any track to the last at options.fps (or the
/// keys' rate): frame f at first + f / fps seconds; a key within 1e-6 s of a
/// frame's time gives its value exactly, else LINEAR interpolates (slerp for
/// rotations), STEP holds, CUBICSPLINE is glTF's Hermite spline (rotations
/// normalised). Throws mf::InputError naming the problem (and the node): no
/// joints ("no armature"), two top joints ("two roots: 'A' and 'B'"), no
/// keys ("no animation"), key times not finite or not increasing, non-finite
/// (NaN) key values, a track whose sizes disagree, too many joints or frames,
/// a degenerate (zero-scale) transform, or a motion that fails
/// Motion::validate.
Motion motion_from_node_animation(const NodeAnimation& animation, const SceneReadOptions& options);

/// Which nodes are joints when a file does not say (no skin): the animated
/// ones and every node between two of them (an animated node above and one
/// below).
std::vector<char> mark_joints(const std::vector<int>& parents, const std::vector<char>& animated);

/// The index of the animation `options` picks among `names`. Throws
/// mf::InputError if there is none ("the file has no animation"), no animation
/// has the name (the names are listed) or the index is out of range.
int pick_animation(const std::vector<std::string>& names, const SceneReadOptions& options);

/// The frame rate of key times `times` (seconds, sorted): one over the
/// smallest interval between keys, snapped to the nearest integer within 1e-3
/// relative (32-bit float key times are not exact); 30 when there is one key.
/// Throws mf::InputError when the rate would exceed 1000 fps.
double fps_from_key_times(const std::vector<double>& times);

}  // namespace mf
