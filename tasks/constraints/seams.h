// How much a completed motion jumps where it leaves or reaches a known frame:
// a completion that continues the keys' motion has no seam; a learned model
// that answers with a pose of its own (motion unlike its training data, e.g.
// a performer standing still on another rig) jumps there by centimetres in
// one frame. The transformer fills interpolate such gaps
// (tasks/transformer/inbetweener_fill.h); the benchmarks log the measure
// (bench/window_log.h).
#pragma once

#include <vector>

#include "prior/motion/motion.h"

namespace mf {

/// One run of unknown frames between two consecutive known frames `from` <
/// `to` - 1: the keys' motion (mean joint distance between the two known
/// frames, cm) and the seam: per boundary the mean over joints of the step
/// (cm) between the known frame and its unknown neighbour in excess of the
/// keys' mean step across the run (their distance over to - from frames),
/// at least 0; the larger of the two boundaries.
struct RunSeam {
  int from = 0, to = 0;
  double key_motion_cm = 0.0;
  double seam_cm = 0.0;
};

/// The runs of `known` (sorted frames of `pose`, positions in metres).
std::vector<RunSeam> run_seams(const GlobalPose& pose, const std::vector<int>& known);

/// The largest seam over the runs of `known` in `result`; 0 without a run.
double seam_excess_cm(const Motion& result, const std::vector<int>& known);

/// True when a run's seam is more than a body can do in one frame at 30 fps:
/// over kMaxSeamCm, or over kMaxSeamShareOfKeyMotion of the keys' own motion.
/// Chosen on the training splits with the two-stage transformer's output
/// (docs/experiments/2026-12-07-interpolated-input.md, "Seams").
inline constexpr double kMaxSeamCm = 8.0;
inline constexpr double kMaxSeamShareOfKeyMotion = 0.3;
bool implausible_seam(const RunSeam& run);

}  // namespace mf
