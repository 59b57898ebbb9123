// Training-data augmentation: more plausible clips made from the training
// split (never from the validation split).
#pragma once

#include <cstdint>
#include <vector>

#include "prior/data/dataset.h"

namespace mf::training {

/// What load_training_data (trainer_util.h) adds to the training split, in
/// this order: mirrors of the originals, then rotation-noise copies of all
/// clips so far, then all clips so far played at each speed.
struct Augmentation {
  bool mirror = false;          ///< each clip's left/right mirror (prior/rig/mirror.h), "<clip>#mirror"
  /// Each clip once more with every non-root joint's frame turned by a
  /// constant random rotation of at most this many degrees (with_frame_noise,
  /// seeded by the clip's name, so every run draws the same; "<clip>#noise"):
  /// the anatomy errors of a retarget from another rig, other performers'
  /// bodies. 0 = none.
  double frame_noise_degrees = 0.0;
  std::vector<double> speeds;   ///< each clip played at these speeds (played_at_speed(), prior/motion/interpolation.h), "<clip>@<speed>x"
};

/// Appends the augmented clips to data.train (see Augmentation). Throws
/// InputError for a speed outside [0.5, 2] or of 1, a frame noise outside
/// [0, 45] degrees, or (with mirror) a rig that cannot be mirrored. With
/// `verbose`, says on stderr what it added.
void augment_training_split(Dataset& data, const Augmentation& a, bool verbose);

/// `motion` with every non-root joint's frame turned by a constant rotation
/// E_j (random axis, angle uniform in [0, max_degrees], drawn from `seed`):
/// world rotations G_j E_j, local rotations E_p^-1 R_j E_j (p the parent,
/// E_root = identity). This is what a retarget whose anatomy is off by E_j
/// gives the model (docs/BENCHMARKS.md: a thigh frame off by half a degree
/// puts the knee off its hinge), and the bones, whose offsets stay fixed in
/// the turned frames, point a little elsewhere, as on another body. The root
/// is then moved up or down so that the mean over frames of the lowest
/// joint's height is unchanged (the feet stay on the floor on average).
Motion with_frame_noise(const Motion& motion, double max_degrees, uint64_t seed);

}  // namespace mf::training
