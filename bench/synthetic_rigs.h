// Synthetic rigs for tests and the benchmark's --rig option: a motion on the
// model's rig (the training data's) rewritten, exactly, onto another humanoid
// rig: other joint names (Mixamo, CMU, LaFAN1, Unreal, Rigify, SMPL
// conventions), another rest pose (T-pose, A-pose, or local frames rotated at
// random), bones scaled, extra joints (fingers, twist bones, a zero-length
// helper, a longer spine), another unit, channel order, container root and
// frame rate. The world motion of every original joint is unchanged (up to the
// bone scale), so a method's quality can be compared with the native rig's.
#pragma once

#include <string>
#include <vector>

#include "prior/motion/bvh.h"
#include "prior/motion/motion.h"
#include "prior/motion/motion_bvh.h"
#include "prior/rig/retarget.h"

namespace mf::bench {

struct RigVariant {
  std::string name;            ///< "mixamo", "cmu", ...
  std::string convention;      ///< naming convention: "mixamo", "mixamo-bare", "cmu", "lafan1", "unreal", "rigify", "smpl", "native"
  std::string rest = "native"; ///< "native", "tpose", "apose" or "random" (local frames rotated at random)
  /// T or A pose: each joint's rest frame turned this many degrees about a
  /// random axis (a pose a person built, not reference_pose()'s exactly).
  double rest_jitter_degrees = 0.0;
  double scale = 1.0;          ///< every bone and the root path
  double length_unit = 0.01;   ///< metres per unit of the BVH file
  bool fingers = false;        ///< two animated finger chains under each hand
  bool twist = false;          ///< a twist joint halfway along each forearm
  bool helper = false;         ///< a zero-length leaf joint on each thigh
  bool extra_spine = false;    ///< the chest bone split in two (a third spine joint)
  bool container = false;      ///< a motionless root joint above the hips in the BVH
  std::string channel_order = "ZXY";  ///< rotation channel order of the non-root joints
  double fps = 0.0;            ///< resampled to this rate when > 0
};

/// The variants the tests and `motionfield-bench --rig` use, by name:
/// "mixamo" (prefixed names, metres, XYZ channels, no container, fingers, a
/// third spine joint, T-pose rest), "cmu" (A-pose, inches, ZYX, 120 fps),
/// "lafan1" (random local frames, centimetres, YXZ), "unreal" (container root,
/// twist bones, 1.3x bones), "rigify" (.L/.R names, metres, 24 fps, 0.7x bones,
/// zero-length helpers), "smpl" (SMPL names, metres, finger joints),
/// "mixamo-rough" (Mixamo's, its T-pose's joints each turned 5 degrees).
std::vector<RigVariant> standard_rig_variants();
/// One of standard_rig_variants() by name; throws InputError listing them.
RigVariant rig_variant(const std::string& name);

/// A motion rewritten onto a variant's rig.
struct VariantMotion {
  Motion motion;        ///< on the variant's skeleton, metres (as read back from `layout`)
  BvhDocument layout;   ///< hierarchy and channels of the variant's BVH file
  BvhUnits units;       ///< its length unit
};

/// Rewrites `motion` (on the model's rig; `anatomy` is that rig's, for the T and
/// A poses) onto `variant`'s rig. Deterministic.
VariantMotion make_variant(const Motion& motion, const RigAnatomy& anatomy, const RigVariant& variant);

}  // namespace mf::bench
