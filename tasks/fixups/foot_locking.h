// Foot locking after a latent solve. Spreading the residuals of the known
// frames over whole gaps (tasks/constraints/residuals.h) makes planted feet slide; this
// takes most of that back: while the global motion predictor says an ankle is
// in contact (probability > 0.5 for at least two frames in a row) and the
// ankle is within its contact threshold of its standing height
// (RigInfo::foot_heights, foot_thresholds), its ground position (x, z) is
// held by two-bone IK on thigh and shin (tasks/fixups/two_bone_ik.h). It is held at
// the ankle's positions at the known frames inside the contact, interpolated
// between them (so that nothing jumps at a known frame), else at the
// contact's mean position, with a ramp of `ramp` frames on each side whose
// weight grows as the square of the distance covered, so that a swinging
// foot is not pulled toward the lock point at once (a key within a ramp
// starts the ramp there).
// Then each toe joint (its name contains "toe") below such an ankle is held
// the same way, in (x, z), while the predictor says it is in contact and it is
// low: with the heel planted (the ankle's lock weight) the foot turns about the
// ankle, with the heel lifted the leg carries the ankle by the toe's step and
// the foot keeps its orientation, in between a mix of the two. Holding the
// toes too took foot skating at a 30-frame gap from 1.24x to 1.12x the ground
// truth's on the validation split at equal L2P (docs/BENCHMARKS.md).
// Frames whose leg joints (or toe) a key constrains, or that carry an
// end-effector target on the leg or on the joints above its hip, are not
// touched; feet without a thigh and a shin below the root are skipped.
//
// Contacts the caller pins (MotionConstraints::contacts) are held the same way,
// on any joint with two bones above it below the root (a foot, a hand), in all
// three coordinates and whatever the predictor says: at the joint's positions
// at the keys inside the pin that fix it (its chain's rotations and the root),
// interpolated between them, else at its mean position over the pin; frames a
// key or an end-effector target protects are left to them.
#pragma once

#include <string>
#include <vector>

#include "prior/model/rig_info.h"
#include "prior/motion/motion.h"
#include "tasks/constraints/motion_constraints.h"

namespace mf {

/// The ramp of contact pins the tasks use (frames on each side).
inline constexpr int kDefaultContactRamp = 3;
/// The ramp of foot locking after a solve or a transformer's pass.
inline constexpr int kFootLockRamp = 5;

/// Locks the feet of `out` (see the top of this file). `contacts` holds the
/// predictor's contact probabilities [frames, rig.num_feet()] row-major.
void lock_feet(const RigInfo& rig, const MotionConstraints& c, const std::vector<float>& contacts, int ramp,
               Motion* out);

/// Holds every contact pin of `c` in `out` (see the top of this file), with a
/// ramp of `ramp` frames on each side. Where the pinned point is beyond the
/// leg's reach from the hip, the root moves toward it by the shortfall, on
/// frames whose root position no key fixes. Returns a warning for each pin that
/// cannot hold exactly: a joint without a two-bone chain, keys inside the pin
/// that place the joint at different points (the pin then moves between them),
/// keys or targets that constrain part of its chain inside the pin.
std::vector<std::string> pin_contacts(const MotionConstraints& c, int ramp, Motion* out);

}  // namespace mf
