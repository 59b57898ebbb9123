// Two-bone inverse kinematics on a Motion: a chain of three joints (a thigh,
// shin and ankle; an upper arm, forearm and hand) bent and turned so that its
// end reaches a point. The fix-ups after a latent solve build on it
// (tasks/fixups/foot_locking.h, tasks/fixups/effector_ik.h).
#pragma once

#include <Eigen/Core>

#include "prior/motion/motion.h"

namespace mf {

/// Moves joint `end` of the chain (top, mid, end) at `frame` to `target`
/// (world, metres) by turning `top` and bending `mid` (the triangle's angle at
/// `mid` from the law of cosines, the bend in the chain's current plane),
/// keeping `end`'s global rotation. A target out of reach is clamped to a
/// tenth of a millimetre inside it. `pose` holds the global transforms of `m`'s
/// current state (forward_kinematics) and is updated for the three joints
/// (not for their descendants). A chain with a zero-length bone is left as it is.
void two_bone_ik(Motion* m, GlobalPose* pose, int frame, int top, int mid, int end, const Eigen::Vector3d& target);

}  // namespace mf
