// Long motions in windows of the model's length: where the windows start, and
// the cross-fade that joins two windows' solutions where they overlap. Used by
// the latent solvers (tasks/latent/latent_solver.h), re-navigation (tasks/renav/renav.h)
// and the prior's codec (tasks/latent/prior_codec.h).
#pragma once

#include <vector>

#include "prior/motion/motion.h"

namespace mf {

/// Window starts for a sequence of `frames` frames cut into windows of
/// `window` frames whose starts are `hop` apart: {0} when frames <= window,
/// else 0, hop, 2 hop, ... (while start + window < frames) and then
/// frames - window, so the last window ends at the last frame and may overlap
/// its predecessor by more than window - hop. Throws mf::InputError unless
/// frames >= 1, window >= 2 and 1 <= hop < window.
std::vector<int> window_starts(int frames, int window, int hop);

/// Blends frame `f` of `piece` into frame `g` of `out`, the piece weighing
/// `w` in [0, 1]: local rotations by SLERP (mf::slerp), the root position by
/// LERP; w >= 1 copies the piece's frame exactly.
void cross_fade_frame(const Motion& piece, int f, double w, Motion* out, int g);

}  // namespace mf
