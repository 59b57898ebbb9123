// Re-navigation: a reference clip plus a new ground path -> a motion that
// follows the path in the reference's style, by optimising the prior's latent
// codes (z_l, z_g) with the network frozen. NeMF's formulation (REFERENCE.md
// section 1) with the soft-DTW divergence of tasks/renav/soft_dtw_kernels.h.
//
// Paths. A ground path is a list of (x, z) points in metres, world frame (Y up,
// prior/motion/skeleton.h; tasks/constraints/ground_path.h). It comes either
//   * per frame: one point per output frame, at the path's frame rate (by
//     default the reference's); the output has exactly as many frames, or
//   * as a polyline: a few vertices, resampled by arc length at constant speed
//     (resample_polyline()) to a number of frames that is given, or by default
//     the one that makes the speed the reference's mean horizontal root speed
//     (polyline_frame_count()).
// Both read from CSV text (tasks/constraints/path_csv.h: one "x,z" pair per line).
//
// Energy of one window of T frames (the model's window or less), in the
// window's canonical frame (below), with weights RenavWeights:
//   path      1   * mean over frames and the two ground axes of the smoothed
//                   absolute difference sqrt(d^2 + 1e-6) (metres) between the
//                   root path the global motion predictor (GMP) gives for the
//                   decoded motion and the target path: NeMF's L1
//   joints    0.5 * soft-DTW divergence (gamma 0.1, squared Euclidean cost) of
//                   the root-relative joint positions in the per-frame heading
//                   frame (heading_relative_positions(), [T, J*3], metres)
//                   between the decoded window and the reference segment
//   heading   1   * soft-DTW divergence of c(t) = cos(angle between the root's
//                   heading and the path tangent at t): for the output, the
//                   decoded heading against the *target* path's tangent; for
//                   the reference, its heading against its own root path's
//                   tangent. So the output keeps the reference's facing
//                   relative to its direction of travel (forward, backward,
//                   sideways) while it follows the new path.
//   foot_skating  (default 0: measured, see docs/BENCHMARKS.md) mean over
//                   frames and feet of p_contact * |v_xz|^2 of the foot joints
//                   (m/s), contacts from the GMP, detached
//   continuity    windows after the first only: over the frames they share
//                   with the already solved previous window, mean squared
//                   geodesic angle of every local rotation (root included) plus
//                   10 x mean squared distance of the heading-frame joint
//                   positions (m^2) against that window's solution
// Tangents: tangent_yaws() of tasks/constraints/ground_path.h (the direction of
// p(t + 2) - p(t - 2)); a reference that never moves uses its own heading (c = 1).
//
// Windows. The solve runs at the model's frame rate: a reference at another
// rate is resampled first (interpolation), the path is resampled in time to
// model frames, and the result is resampled back to the path's rate (so the
// output has exactly as many frames as the path). Paths longer than the
// model's window are cut into windows of the window's length overlapping by a
// quarter of it, solved one after the other: each later window starts where
// the previous solution is at its first frame (position and heading), is
// pulled toward that solution on the shared frames (continuity) and is
// cross-faded with it there (SLERP / LERP, linear weights), so there is no
// seam (the window loop of tasks/latent/window_solver.h). Each window is compared with a reference segment of its own length:
// the same frames of the reference when the reference is at least as long as
// the (model-rate) path; otherwise segments spread evenly over the reference
// (window k of K starts at reference frame round(s_k (R - T) / (M - T))), so
// a short reference is replayed with overlaps; a reference shorter than one
// window is used whole (soft-DTW aligns sequences of different lengths).
// After the last window the feet are locked where the global motion
// predictor says they are in contact (RenavOptions::foot_lock_ramp,
// tasks/fixups/foot_locking.h), before the result goes back to the path's rate.
//
// Canonical frame of a window: origin at the path's first point (later
// windows: the previous solution's root there), turned about +Y so that the
// expected heading at the first frame (path tangent plus the reference's
// facing offset; later windows: the previous solution's heading) is +Z.
// The GMP's root path starts at that origin, so the output starts exactly at
// the path's first point.
//
// Pace (RenavOptions::match_pace): a path walked faster or slower than the
// reference is followed with the reference played at the path's pace (time
// scaled by the ratio of their mean ground speeds, reference_pace(); at most
// 2x either way; a reference that would be left with fewer than two frames
// at the model's rate keeps its own). Why: the joints' soft-DTW aligns in
// time but still asks for as many steps as the reference takes, which holds
// the motion back on a faster path and pushes it past the end of a slower one.
//
// Initialisation (per window), NeMF's and ours, the lowest energy kept:
// z_l is the encoder's mean on the reference segment; z_g is, in turn, the
// encoder's mean on the reference segment turned to follow the target path
// (each frame's root turned about +Y by the angle between the target's and
// the reference's travel directions, root placed on the path: "turned"), on
// the untouched reference ("reference"), and NeMF's random draw from N(0, I)
// seeded by TaskContext::seed ("random").
//
// Solvers: L-BFGS (Ceres GradientProblemSolver, the default, method "nemf")
// or NeMF's Adam (lr 0.1, decay x0.7 every 200, up to 600 iterations, method
// "nemf-adam"). Either minimises the energy on the Eigen runtime
// (tasks/renav/renav_runtime_energy.h; tasks/reference/renav_energy.h is the
// libtorch reference it is tested against), the initial codes come from its
// encoders (NemfRuntime::encode_rotations) and the solution is decoded on it.
// Both stop early,
// report progress once per iteration (TaskContext::report: the callback and
// the cancel flag can stop them: CancelledError) and fill a per-window summary. Deterministic for a given input,
// options, seed and thread count.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "prior/motion/motion.h"
#include "tasks/constraints/ground_path.h"
#include "tasks/constraints/path_csv.h"  // parse_path_csv(), read_path_csv() for the callers
#include "tasks/context/task_context.h"
#include "tasks/fixups/foot_locking.h"
#include "tasks/latent/latent_optimizer.h"
#include "tasks/latent/window_solver.h"
#include "tasks/renav/renav_window.h"

namespace mf {

namespace runtime {
class NemfRuntime;
}

// ---------------------------------------------------------------- the energy

/// The problem of output frames [begin, begin + length) of a model-rate target
/// path `path` (world (x, z) per model frame): the reference segment
/// [ref_begin, ref_begin + ref_length) of `reference` (model fps, the model's
/// skeleton). `previous` (optional) is the already solved output so far (model
/// fps, world) whose frames [begin, begin + shared) are shared with this window;
/// with shared = 0 the window starts at path[begin] heading along the target
/// with the reference's facing offset. Throws mf::InputError on bad ranges or a
/// skeleton that does not match the model.
RenavWindow make_renav_window(const runtime::NemfRuntime& model, const Motion& reference, int ref_begin, int ref_length,
                              const std::vector<Eigen::Vector2d>& path, int begin, int length,
                              const Motion* previous = nullptr, int shared = 0);

// ---------------------------------------------------------------- the solve

/// The options of renavigate(). The optimiser and its settings are embedded
/// (LatentOptimizerSettings) with re-navigation's defaults: max_iterations
/// is the cap per window, 0 = the solver's default (L-BFGS 100, Adam 600);
/// function tolerance 1e-5, gradient tolerance 1e-8, parameter tolerance
/// 1e-7, L-BFGS rank 20; Adam lr 0.1, x0.7 every 200 iterations, stopping when
/// the best energy improves by less than 1e-4 over 100 iterations.
struct RenavOptions : LatentOptimizerSettings {
  RenavOptions() {
    function_tolerance = 1e-5;
    parameter_tolerance = 1e-7;
  }

  RenavWeights weights;
  /// Initial z_g candidates tried, among "turned", "reference", "random"
  /// (see the top of this file); the lowest energy is kept. Empty = all three.
  std::vector<std::string> inits;
  /// Frames shared by consecutive windows (at most half the model's window);
  /// 0 = a quarter of the model's window.
  int overlap = 0;
  /// Foot locking after the solve (tasks/fixups/foot_locking.h, with the global
  /// motion predictor's contacts of the decoded windows, cross-faded as the
  /// poses are), with a ramp of this many frames; negative: off.
  int foot_lock_ramp = kFootLockRamp;
  /// Pace: when the path is walked faster or slower than the reference (by
  /// more than 5 %), the reference is first played faster or slower
  /// (played_at_speed() by reference_pace(), at most 2x either way)
  /// so that the style terms do not pull the motion back to the reference's
  /// own pace and off a faster or slower path. false: the reference as it is.
  bool match_pace = true;

  /// Empty when valid, else what is wrong.
  std::string validate() const;
};

/// The playback speeds match_pace may apply to a reference.
constexpr double kMinPace = 0.5, kMaxPace = 2.0;

/// The speed factor match_pace applies: the path's mean ground speed (points
/// at `path_fps`) over the reference's (mean_ground_speed()), clamped to
/// [kMinPace, kMaxPace]; 1 when within 5 % of 1, when the reference barely
/// moves (under 0.05 m/s: a clip in place has no pace to match) or the path
/// has one point. (Matching the distance the reference covers over the
/// compared frames instead also re-timed references whose start is slower or
/// faster than their mean, at no gain in path error: docs/BENCHMARKS.md,
/// "Re-navigation".)
double reference_pace(const Motion& reference, const std::vector<Eigen::Vector2d>& path, double path_fps);

/// The options of the methods "nemf" (L-BFGS) and "nemf-adam".
RenavOptions default_renav_options(LatentOptimizer optimizer = LatentOptimizer::Lbfgs);

/// What one window's solve did: the optimiser's summary (wall_ms includes the
/// window's initialisation) and where the window lies.
struct RenavWindowSummary : SolveSummary {
  int begin = 0, length = 0;           ///< output frames (model fps)
  /// The span of the reference this window was compared with, in seconds of
  /// the reference as given (before match_pace played it faster or slower).
  double reference_from = 0.0, reference_to = 0.0;
  std::string init;                    ///< the initial z_g kept
  std::vector<std::pair<std::string, double>> init_energies;  ///< each candidate's energy
};

struct RenavReport {
  std::vector<RenavWindowSummary> windows;
  int iterations = 0;                  ///< summed over windows
  double path_error_mean_cm = 0.0;     ///< output root vs target path, horizontal, over output frames
  double path_error_max_cm = 0.0;
  double pace = 1.0;                   ///< the reference's playback speed (RenavOptions::match_pace)
  double wall_ms = 0.0;
};

/// Re-navigates `reference` (>= 2 frames, any fps, on the model's skeleton:
/// same joint names and parents) along `path` (per-frame points at
/// `path_fps`, validated with validate_path()). The output has the
/// reference's skeleton, path.size() frames, fps = path_fps. Throws
/// mf::InputError on bad input or options, CancelledError when cancelled.
Motion renavigate(const runtime::NemfRuntime& model, const Motion& reference, const std::vector<Eigen::Vector2d>& path,
                  double path_fps, const RenavOptions& options, const TaskContext& ctx = {},
                  RenavReport* report = nullptr);

/// The re-navigation methods, the default first: {"nemf", "nemf-adam"}.
std::vector<std::string> renav_methods();

/// The task entry point (the CLI, the C API, the benchmark): `method` empty =
/// "nemf"; an unknown name throws InputError listing renav_methods(); no model
/// in `ctx` throws ModelMissingError; a reference on a rig that cannot be
/// served fails as check_model_rig (tasks/context/model_rig.h) says. path_fps <= 0 means the reference's fps.
/// A reference on another humanoid rig than the model's is retargeted to it
/// (tasks/context/model_rig.h: needs ctx.model_anatomy; ctx.rig_map applies), the
/// path (the reference's metres) scaled by the rigs' size ratio, and the
/// result brought back onto the reference's rig, joints the model lacks
/// holding the reference's first pose; the report's path errors are then in
/// the reference's centimetres.
Motion run_renav(const Motion& reference, const std::vector<Eigen::Vector2d>& path, double path_fps,
                 const std::string& method, const TaskContext& ctx, RenavReport* report = nullptr);

}  // namespace mf
