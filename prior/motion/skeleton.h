// Skeleton: joint names, parents and rest offsets.
//
// Conventions used throughout motionfield (the "internal representation"):
//   * lengths in metres, time in seconds;
//   * Y is up, the ground is the XZ plane at y = 0;
//   * quaternions are Hamilton, unit, stored (w, x, y, z), rotating column
//     vectors actively: v' = q v q^-1; a joint's local rotation maps its own
//     frame into its parent's frame;
//   * global transform of joint j: G_j = G_parent * T(offset_j) * R_j, the root
//     uses its per-frame translation instead of its offset.
// Conversions to other units or axes happen only at the BVH and C boundaries.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace mf {

struct Skeleton {
  std::vector<std::string> names;        ///< unique joint names
  std::vector<int> parents;              ///< parent index, -1 for the root (joint 0 only)
  std::vector<Eigen::Vector3d> offsets;  ///< rest offset from the parent, metres, parent frame

  int num_joints() const { return static_cast<int>(names.size()); }

  /// Index of the joint named `name`, or -1.
  int find(const std::string& name) const;

  /// Throws mf::InputError unless: at least one joint; sizes agree; exactly one
  /// root and it is joint 0; every parent comes before its child (which also
  /// rules out cycles); names are non-empty and unique; offsets are finite.
  void validate() const;

  /// True if both skeletons have the same joint names and parents in the same
  /// order and offsets equal within `tolerance` metres. The root's offset (its
  /// rest position, unused by forward kinematics: motions carry their own root
  /// positions) is not compared, so clips of one rig recorded at different
  /// places are on the same skeleton.
  bool same_as(const Skeleton& other, double tolerance = 1e-4) const;

  /// Children of every joint, in index order.
  std::vector<std::vector<int>> children() const;
};

}  // namespace mf
