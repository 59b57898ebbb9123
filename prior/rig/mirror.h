// Left/right mirroring of motions on a symmetric humanoid rig (training data
// augmentation: a mirrored clip is as plausible as the original, and the
// training set doubles).
//
// The mirrored motion is the original seen in a vertical mirror (world
// reflection M = diag(-1, 1, 1), Y up) with every joint's role taken by its
// counterpart c(j) (rig_map.h mirror_counterparts: "UpperArm_L" <->
// "UpperArm_R"; c(j) = j on the midline): world positions x'_j = M x_c(j).
// Joint frames of BVH rigs are rarely world-aligned, so each joint gets a
// local reflection S_j (one of the four sign-flip matrices of determinant -1)
// with world rotations G'_j = M G_c(j) S_j, which gives local rotations
//   root     R'_0 = M R_0 S_0
//   others   R'_j = S_p R_c(j) S_j   (p the parent; proper rotations)
// S_p must map the counterparts' rest offsets onto the children's
// (S_p o_c(k) = o_k), which fixes S_p up to a twist about a bone; the twist is
// chosen so that the mirrored motion's mean local rotations match the
// original's (a symmetric body moves alike on both sides), using mean local
// rotations measured on the data. Rigs whose left and right joint frames are
// mirror images up to axis flips (rigs mirrored in a DCC tool) qualify.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "prior/motion/motion.h"

namespace mf {

struct MirrorMap {
  std::vector<int> counterpart;          ///< per joint, its left/right counterpart (itself on the midline)
  std::vector<Eigen::Matrix3d> reflection;  ///< per joint, S_j
  /// The largest |S_p o_c(k) - o_k| over the joints, metres (0 for a rig
  /// whose rest offsets mirror exactly).
  double max_asymmetry = 0.0;
};

/// Mean local rotation of every joint over `motions` (sign-aligned quaternion
/// average), the statistics mirror_map chooses the twists with.
std::vector<Eigen::Quaterniond> mean_local_rotations(const std::vector<const Motion*>& motions);

/// The mirror of `skeleton` given the data's mean local rotations
/// (mean_local_rotations). Throws mf::InputError when the names do not pair
/// up (mirror_counterparts) or when no reflection of a joint maps its
/// children's counterparts' rest offsets onto theirs within `tolerance`
/// metres plus 5 % of their length.
MirrorMap mirror_map(const Skeleton& skeleton, const std::vector<Eigen::Quaterniond>& mean_local,
                     double tolerance = 0.01);

/// The mirrored motion (same skeleton, fps and length); `map` must be
/// mirror_map of motion.skeleton.
Motion mirror_motion(const Motion& motion, const MirrorMap& map);

}  // namespace mf
