// The ground a motion stands on, for the learned methods: the prior and the
// transformers were trained on capture whose floor is at height zero, and
// their root heights are absolute. A user's keys on a platform, a step or in a
// file whose floor is elsewhere (real BVH files put it anywhere) would be
// pulled to that floor. The model-rig adapter (tasks/context/model_rig.h) therefore
// lowers the motion by the ground under the known frames before a learned
// method sees it and raises the result by the same amount afterwards.
#pragma once

#include <vector>

#include "prior/model/rig_info.h"
#include "prior/motion/motion.h"

namespace mf {

/// The ground's height under every frame of `motion` (on the model's rig
/// `rig`, metres), read from the frames `known` (sorted, non-empty): at each
/// known frame, the lowest foot joint's height above its standing height
/// (RigInfo::foot_heights); then, so that a key in the air does not lift the
/// ground, the lowest of those within `envelope_frames` of each known frame;
/// interpolated linearly between known frames and held before the first and
/// after the last. Small offsets count too: on real CMU capture, where the
/// retargeted floor is a few centimetres off the training data's, ignoring
/// offsets under 3 cm made the transformer alone 4-17 % worse at gap 30
/// (docs/BENCHMARKS.md, "Real capture on other rigs"). Zero everywhere when the rig has no feet. Unknown
/// frames are never read.
std::vector<double> ground_heights(const Motion& motion, const std::vector<int>& known, const RigInfo& rig,
                                   int envelope_frames);

/// Adds sign * heights[f] to the root's height (y) at every frame f.
/// heights.size() must equal motion->num_frames().
void shift_root_heights(Motion* motion, const std::vector<double>& heights, double sign);

}  // namespace mf
