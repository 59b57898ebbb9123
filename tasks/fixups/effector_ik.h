// End-effector IK after a latent solve: the energy pulls a target joint
// toward its target, and this places it there exactly. Each target is reached
// by two-bone IK (tasks/fixups/two_bone_ik.h) on the target joint's chain (the
// joint, its parent and grandparent, the grandparent not the root), and the
// same displacement is spread over `falloff` frames on each side with
// raised-cosine weights, stopping at frames whose chain a key constrains. A
// target beyond the chain's reach is first brought within it by swinging the
// chain's parent (a shoulder) and, if that is not enough or the chain hangs
// from the root (a leg), by moving the root, with the same falloff and never
// at keys that fix those values.
#pragma once

#include "prior/motion/motion.h"
#include "tasks/constraints/motion_constraints.h"

namespace mf {

/// The falloff the tasks use (frames on each side of a target).
inline constexpr int kDefaultEffectorFalloff = 10;

/// Reaches every end-effector target of `c` in `out` (see the top of this
/// file); targets with weight 0, on a joint whose chain a key constrains at
/// the target's frame, or on a chain too short (its grandparent the root or
/// missing) are left alone. Two passes, so that a later target's root shift
/// does not undo an earlier one.
void reach_effectors(const MotionConstraints& c, int falloff, Motion* out);

}  // namespace mf
