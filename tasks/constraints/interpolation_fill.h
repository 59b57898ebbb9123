// Interpolation under keys, the non-learned fill of every task: interpolation
// and zero velocity between whole-pose keys (prior/motion/interpolation.h,
// re-exported here), and interpolation under partial keys. They read only the
// known frames or keys of their input and throw mf::InputError on arguments
// that would make them read out of bounds. The baseline methods
// (tasks/methods/baselines.cc) run them.
#pragma once

#include <vector>

#include "prior/motion/interpolation.h"
#include "prior/motion/motion.h"
#include "tasks/constraints/motion_constraints.h"

namespace mf {

/// Interpolation under partial keys, the fill of the latent solvers' default
/// initialiser (tasks/latent/initializers.h): a motion of `window`'s length whose
/// constrained values are those of `window`. With full-pose keys only it is
/// interpolate_motion() over the key frames; otherwise each joint's rotation
/// is interpolated (SLERP) over the keys that constrain it, the root position
/// (LERP) over the keys that give it, each held before its first and after its
/// last key, and a joint no key constrains keeps the identity (a root
/// position no key gives, zero). Reads only what `constraints` names; throws
/// mf::InputError without keys.
Motion fill_by_interpolation(const Motion& window, const MotionConstraints& constraints);

}  // namespace mf
