// The benchmark protocol of motionfield-bench (docs/BENCHMARKS.md): LaFAN1-style
// windows cut from held-out clips, each task run through the task entry points
// of tasks/methods/jobs.h with a named method, and the metrics of bench/metrics.h
// summarised in one markdown table per (task, method).
//
// Tasks (defaults of ProtocolOptions):
// * Gap filling ("gap"): windows of context (10) + T + 1 frames for T in
//   {5, 15, 30, 45, 90}, starting every 40 frames in each clip (only windows
//   that fit), canonicalised at frame context - 1 (9). The method sees the
//   window with frames [context, context + T) unknown (mf::run_fill); metrics
//   over those T frames, known-frame error over the others.
// * Sparse keyframes ("sparse"): windows of 128 frames every 40 frames,
//   keyframes 0, k, 2k, ... and the last frame for k in {5, 10, 15, 20, 30}
//   (mf::run_inbetween), canonicalised at frame 0; metrics over the other
//   frames, known-frame error over the keyframes.
// * Resampling 15 -> 30 fps ("resample"): windows of 65 frames every 40 frames;
//   the input is the even frames at half the frame rate (33 frames), resampled
//   with mf::run_resample back to the clip's rate (65 frames); canonicalised at
//   frame 0; metrics over the odd frames, known-frame error over the even ones.
//
// Methods get an mf::TaskContext (the prior, loaded once by the caller, for the
// methods that need it). The prior's own evaluation (reconstruction, frame
// rates, seams, samples) is in bench/prior_eval.h.
//
// Every window is canonicalised (bench/metrics.h) before the method sees it, so
// truth and prediction share the frame; frames the method must not know are
// overwritten (identity rotations, the previous known root position) before
// the call, so no method can read the answer. Wall time per window counts the
// method call only.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bench/metrics.h"
#include "bench/motion_features.h"
#include "bench/window_log.h"
#include "prior/data/dataset.h"
#include "prior/rig/retarget.h"
#include "tasks/constraints/motion_constraints.h"
#include "tasks/methods/method.h"

namespace mf::bench {

enum class Task { Gap, Sparse, Resample };

/// "gap", "sparse", "resample".
const char* task_name(Task task);
/// Inverse of task_name; throws mf::InputError on an unknown name.
Task task_from_name(const std::string& name);
/// Every task in the order of the tables.
std::vector<Task> all_tasks();

/// One resampling row: the input is every `in_step`-th frame of the ground
/// truth (at fps / in_step), the method brings it to fps / out_step and is
/// scored on every out_step-th frame of the ground truth. {k, 1}: back to the
/// full rate ("k"); {5, 4}: a 1.25 ratio (6 -> 7.5 fps at 30, as 24 -> 30);
/// {4, 5}: downsampling by 0.8 (as 30 -> 24).
struct ResampleRatio {
  int in_step = 2, out_step = 1;
  /// "k" when out_step is 1, else "in_step:out_step".
  std::string label() const;
};

/// Parses "k" or "a:b" (whole numbers >= 1, not both 1); throws mf::InputError.
ResampleRatio parse_resample_ratio(const std::string& text);

struct ProtocolOptions {
  std::vector<int> gap_lengths{5, 15, 30, 45, 90};
  std::vector<int> keyframe_spacings{5, 10, 15, 20, 30};
  int context = 10;            ///< gap filling: known frames before the gap
  int stride = 40;             ///< window start every `stride` frames
  int sparse_window = 128;
  /// Resampling windows: the smallest 1 + a multiple of lcm(in_step,
  /// out_step) frames that is at least this, so that both ends are input and
  /// output frames (65 for steps dividing 64).
  int resample_window = 65;
  /// Resampling rows (ResampleRatio): the default 15 -> 30 fps.
  std::vector<ResampleRatio> resample_ratios{{2, 1}};
  int max_windows = 0;         ///< cap per table row (spread evenly over the windows); 0 = all
  Eigen::Vector3d root_forward = Eigen::Vector3d::UnitZ();
  /// Gap filling and sparse keyframes on a synthetic rig (bench/synthetic_rigs.h,
  /// by name; empty: the native rig): each window is rewritten onto it, the
  /// method sees it there (at the rig's frame rate, indices scaled; only rates
  /// that are whole multiples of the native one), and its result is brought back
  /// to the native rig exactly (anatomies measured on the whole truth window)
  /// for the metrics. `rig_anatomy`: the native rig's, for the rig's rest pose.
  std::string rig;
  std::shared_ptr<const RigAnatomy> rig_anatomy;
  /// Gap filling: give the method the ground truth's trajectory of the gap
  /// frames (MotionConstraints::trajectory, the window's canonical frame) and
  /// run it through mf::run_constrained (methods without complete_constrained
  /// are then not supported). Native rig only.
  bool trajectory = false;
  /// Add the L2T column (MetricSummary::l2t) to the tables.
  bool l2t = false;
  /// Clips on their own rigs (the foreign capture, bench/foreign_data.h): one
  /// retargeter onto the model's rig per clip of `clips` (anatomies from the
  /// whole clip). The method sees each window as the clip has it (its own
  /// world, ground height and facing; unknown frames hidden), as a user's file
  /// reaches the CLI; its result and the truth are then both mapped onto the
  /// model's rig and canonicalised by the truth's transform for the metrics.
  /// Empty: the clips are on the native rig.
  std::vector<std::shared_ptr<const Retargeter>> clip_to_model;
  /// When set, every scored window is also recorded there (bench/window_log.h),
  /// with the method's diagnostics (TaskContext::diagnostics). Not owned.
  WindowLog* window_log = nullptr;
  /// When both are set, every scored window's truth and prediction also go
  /// through the feature extractor into `feature_sets` (bench/motion_features.h)
  /// as the set "TASK ROW / METHOD". Not owned.
  const MotionFeatures* features = nullptr;
  FeatureSets* feature_sets = nullptr;
};

/// The ground truth's trajectory rows (trajectory_features(), frames a..b-1)
/// of `truth` as MotionConstraints::trajectory.
std::vector<TrajectoryPoint> truth_trajectory(const Motion& truth, int a, int b, const Eigen::Vector3d& root_forward);

/// Windows of `length` frames starting at 0, stride, 2 stride, ... in each
/// clip, only those that fit (start + length <= frames), clip by clip in order.
/// Throws mf::InputError unless length >= 1 and stride >= 1.
std::vector<Window> protocol_windows(const std::vector<Clip>& clips, int length, int stride);

/// At most `max_windows` of `windows`, spread evenly (indices floor(i * n / max));
/// all of them when max_windows <= 0 or there are not more.
std::vector<Window> cap_windows(const std::vector<Window>& windows, int max_windows);

/// Keyframes 0, spacing, 2 spacing, ... below `frames`, plus frames - 1.
/// Throws mf::InputError unless spacing >= 1 and frames >= 2.
std::vector<int> sparse_keyframes(int frames, int spacing);

/// A copy of `motion` whose frames outside `known` (sorted, non-empty) hold
/// identity rotations and the root position of the last known frame before
/// them (the first known frame for frames before it).
Motion hide_unknown_frames(const Motion& motion, const std::vector<int>& known);

/// One table row: one gap length / keyframe spacing.
struct RowResult {
  int parameter = 0;           ///< T, k, or the input step for resampling
  std::string label;           ///< resampling: ResampleRatio::label(); else empty (the table shows `parameter`)
  MetricSummary metrics;
  double ms_per_window = 0.0;  ///< wall time of the method call per window
};

struct TaskResult {
  Task task = Task::Gap;
  std::string method;
  int threads = 1;             ///< torch intra-op threads during the run
  bool trajectory = false;     ///< the method was given the ground-truth trajectory
  bool l2t = false;            ///< format_table shows L2T
  std::vector<RowResult> rows;
};

/// The three tasks on `clips` (the validation split) with `method` (a name of
/// mf::available_methods()). `ctx` is handed to every method call (the prior
/// for methods with needs_model; a method that needs one throws mf::InputError
/// without it). Rows without any window are kept with zero windows. Errors of
/// the method propagate.
TaskResult run_gap_filling(const std::vector<Clip>& clips, const EvalStats& stats, const std::string& method,
                           const ProtocolOptions& options = {}, const TaskContext& ctx = {});
TaskResult run_sparse_keyframes(const std::vector<Clip>& clips, const EvalStats& stats, const std::string& method,
                                const ProtocolOptions& options = {}, const TaskContext& ctx = {});
TaskResult run_resampling(const std::vector<Clip>& clips, const EvalStats& stats, const std::string& method,
                          const ProtocolOptions& options = {}, const TaskContext& ctx = {});
TaskResult run_task(Task task, const std::vector<Clip>& clips, const EvalStats& stats, const std::string& method,
                    const ProtocolOptions& options = {}, const TaskContext& ctx = {});

/// Whether `method` (a registered name) supports `task` (complete for gap and
/// sparse, resample for resample); false for unknown names.
bool method_supports(const std::string& method, Task task);

/// The markdown table of a result, with a heading line naming the task, the
/// method and the torch thread count. With `l2p_axes`, two more columns split
/// L2P into its horizontal (x, z) and vertical (y) parts.
std::string format_table(const TaskResult& result, bool l2p_axes = false);

/// A markdown table of the evaluation statistics: per joint, the mean and
/// standard deviation (cm) of each canonical position coordinate, and the
/// standing height and contact threshold of the foot joints.
std::string format_eval_stats(const EvalStats& stats);

}  // namespace mf::bench
