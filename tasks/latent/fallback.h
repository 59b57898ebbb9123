// When the prior cannot reach the keys, interpolation. On motion unlike its
// training data (real capture of other performers: salsa, standing idle) the
// latent solvers end far from the known frames and lose to interpolation on
// most windows, and even a perfect per-window choice gains at most a few per
// cent over interpolation there (docs/experiments/2026-12-06-never-worse-signals.md).
// The solver's own final fit to the keys tells those windows apart from the
// training data's motion by about an order of magnitude: a window whose
// weighted data terms (rotation, root orientation, position, root translation:
// means over the known entries) exceed `always_above`, or exceed both
// `max_data_terms` and `max_data_terms_per_cm` times how far its keys move
// (still motion the prior cannot hold), is replaced by interpolation of its
// keys, cross-faded over the frames it shares with windows that were kept.
#pragma once

#include <string>
#include <vector>

#include "prior/motion/motion.h"
#include "tasks/latent/window_solver.h"

namespace mf {

/// The rule, with its thresholds: chosen for the shipped prior by
/// scripts/fallback-thresholds.py on the training splits of the Bandai Namco
/// data and the foreign capture at gaps of 15, 30 and 45 frames and keys every
/// 15 and 30 frames, so that no Bandai row loses more than 0.01 of its ratio to
/// interpolation and the hand-made sample walk (samples/walk_keyframes.bvh:
/// fits 0.08-0.13 at 52-95 cm of key motion) keeps the solver's result
/// (docs/BENCHMARKS.md, "Real capture on other rigs").
struct InterpolationFallback {
  bool enabled = false;
  double always_above = 0.15;
  double max_data_terms = 0.035;
  double max_data_terms_per_cm = 0.01;
  /// Blend toward the input as given (its unknown frames already hold a
  /// start, as resampling's quintic) instead of toward interpolation between
  /// the known frames.
  bool toward_input = false;
};

/// What the rule saw in one window, and what it chose.
struct WindowTrust {
  double data_terms = 0.0;     ///< the window's final weighted data terms, summed
  double key_motion_cm = 0.0;  ///< key_motion_cm() of the window
  bool interpolated = false;   ///< the window's frames are interpolation's
};

/// The sum of the data terms among `summary`'s final terms.
double final_data_terms(const SolveSummary& summary);

/// How far the keys move: over the runs of unknown frames between two of the
/// `known` frames (sorted), the mean joint distance in cm between the known
/// frames at either end, averaged over the runs; 0 without such a run. Reads
/// only the known frames of `motion` (positions in metres).
double key_motion_cm(const Motion& motion, const std::vector<int>& known);

/// Applies `rule` to one window's solve.
WindowTrust judge_window(const InterpolationFallback& rule, const SolveSummary& summary, const Motion& window,
                         const std::vector<int>& known);

/// Per output frame, the weight of interpolation (0..1): 1 on frames only
/// interpolated windows cover, 0 on frames only kept ones cover, and a linear
/// ramp over the frames two windows share. `spans` and `trust` in solve order.
std::vector<double> interpolation_weights(const std::vector<WindowSpan>& spans, const std::vector<WindowTrust>& trust,
                                          int frames);

/// `solved` moved toward `interpolated` by `weights` (rotations SLERP, root
/// LERP), and the foot contact probabilities ([frames, feet]) scaled by
/// 1 - weight, so that nothing is locked where interpolation runs.
void blend_toward_interpolation(const Motion& interpolated, const std::vector<double>& weights, Motion* solved,
                                std::vector<float>* contacts);

/// One sentence for the user about the windows that fell back ("" when none).
std::string fallback_note(const std::vector<WindowTrust>& trust, const InterpolationFallback& rule);

}  // namespace mf
