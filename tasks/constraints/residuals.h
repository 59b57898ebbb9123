// Known values made exact without a jump. A solution (a decoded window, a
// motion brought back from the model's rig) misses the values it was given at
// the known frames by a little; copying the given values there would make the
// motion jump. Instead the residual at each known frame (given value vs the
// solution's) is spread over the frames around it: between two known frames
// it ramps from one's residual to the other's, before the first and after the
// last it is held, and at the known frames the given values are copied bit
// for bit. Rotations: the residual is the rotation r = given * solution^-1,
// interpolated by SLERP and applied on the left; root positions: the
// difference, interpolated by LERP and added.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

#include "prior/motion/motion.h"
#include "tasks/constraints/residual_bracket.h"

namespace mf {

/// The rotation residual given * solution^-1 (both normalised; normalised).
Eigen::Quaterniond rotation_residual(const Eigen::Quaterniond& given, const Eigen::Quaterniond& solution);

/// Makes the local rotation of `joint` in `out` at the sorted, unique
/// `frames` exactly `given`'s and spreads the residual against `solution`
/// over every other frame of `out` (see the top of this file). `given` is
/// read only at `frames`; `solution` and `out` have the same frames and
/// joints (`out` may start as a copy of `solution`). No frames: no change.
void spread_rotation_residual(const Motion& given, const Motion& solution, int joint, const std::vector<int>& frames,
                              ResidualRamp ramp, Motion* out);

/// The same for the root position.
void spread_root_residual(const Motion& given, const Motion& solution, const std::vector<int>& frames,
                          ResidualRamp ramp, Motion* out);

}  // namespace mf
