// Conversion between BVH documents (file units, Euler degrees) and mf::Motion
// (metres, quaternions). This is the BVH boundary of the internal representation.
//
// Container roots: when the BVH root has exactly one child joint and that child
// has position channels (as in rigs whose "joint_Root" sits at the origin and
// whose hips carry the motion), the root is a container. Its transform is
// composed into the child, which becomes the motion's root; on writing, the
// container's channels are written as identity / its offset and the child's
// channels carry the whole root motion, so every global pose is preserved.
// Position channels on other non-root joints replace the offset: their frame-0
// value becomes the motion skeleton's offset (animated bone lengths are not
// represented).
#pragma once

#include "prior/motion/bvh.h"
#include "prior/motion/motion.h"

namespace mf {

struct BvhUnits {
  /// Metres per file length unit: 0.01 for centimetres (the default, as in most
  /// mocap BVH), 1 for metres.
  double length_scale = 0.01;
};

/// Rotation channels (degrees) become quaternions through quat_from_euler in the
/// joint's own channel order; position channels are applied before the rotation
/// (T * R) whatever their place in the channel list. A motion root without
/// position channels keeps its OFFSET as a constant translation. The skeleton's
/// root offset (unused by FK) is the root's rest position: its OFFSET, plus the
/// container's. Quaternion signs are made continuous in time (frame 0 has
/// w >= 0). fps = 1 / frame_time, snapped to the nearest integer when within
/// 1e-5 relative (a frame time of 0.0333333 gives exactly 30).
/// Throws mf::InputError if the document is invalid (BvhDocument::validate), has
/// no frames or a frame time <= 0, a joint's rotation channels are not three
/// distinct axes (or absent), or units.length_scale is not positive and finite.
Motion motion_from_bvh(const BvhDocument& doc, const BvhUnits& units = {});

/// Writes `motion` with the hierarchy, channel layout, End Sites and joint order
/// of `layout` (the input document, typically; its values are ignored). Joints
/// are matched by name; every joint of the motion's skeleton must exist in the
/// layout with the same parent, and vice versa (except a container root, see
/// above). Offsets come from the motion's skeleton (divided by length_scale),
/// except the root's, which keeps the layout's; position channels of non-root
/// joints are written as those offsets. frame_time = 1 / motion.fps. Euler
/// angles are extracted continuously from frame to frame (euler_from_quat on
/// frame 0, then euler_from_quat_near the previous frame).
/// Throws mf::InputError on a skeleton/layout mismatch, an invalid motion or
/// layout, or motion the layout cannot carry: a root translation along an axis
/// without a position channel that differs from the OFFSET, or a rotation of a
/// joint without rotation channels (tolerance 1e-6 m / 1e-6 rad).
BvhDocument motion_to_bvh(const Motion& motion, const BvhDocument& layout, const BvhUnits& units = {});

/// A layout for a motion with no source file, joints in depth-first order (the
/// skeleton's children in index order): the root with the channels
/// "Xposition Yposition Zposition Zrotation Xrotation Yrotation", the other
/// joints "Zrotation Xrotation Yrotation"; offsets = skeleton offsets /
/// length_scale; End Sites on leaves, a quarter of the leaf's own offset
/// (5 cm up if that offset is zero). num_frames = 0, no values.
BvhDocument default_bvh_layout(const Skeleton& skeleton, const BvhUnits& units = {});

/// Convenience: read a BVH file into a Motion (and its document, for writing
/// back). Parse errors are BvhError ("<path>:<line>: ..."); conversion errors
/// are InputError prefixed with "<path>: ".
Motion read_motion(const std::string& path, BvhDocument* layout_out = nullptr, const BvhUnits& units = {});
/// motion_to_bvh then write_bvh_file.
void write_motion(const std::string& path, const Motion& motion, const BvhDocument& layout,
                  const BvhUnits& units = {});

}  // namespace mf
