// The prior's own evaluation in motionfield-bench (docs/BENCHMARKS.md, tasks
// recon, fps, seams and sample): reconstruction, decoding at other frame rates,
// seams between overlapping windows, and samples from N(0, I). Every task goes
// through the codec of tasks/latent/prior_codec.h, as the tasks and the C API do.
//
// Reconstruction metrics (NeMF, REFERENCE.md section 1), between a truth and
// its reconstruction in the same world frame (the codec places the
// reconstruction in the truth's frame at the window start, which is the
// window's canonical frame up to a rigid motion; distances and angles do not
// change under it):
//   MRE (deg)  mean geodesic angle of the local rotations of the non-root
//              joints, over frames and joints;
//   MOE (deg)  mean geodesic angle of the root orientation (joint 0), over frames;
//   MPE (cm)   mean distance between root-relative joint positions (global
//              position minus the root's, so the root orientation counts; the
//              root itself, always 0, is left out), over frames and non-root joints;
//   MTE (cm)   mean distance between the root positions (the reconstruction's
//              comes from the global motion predictor), over frames;
//   FDE (cm)   mean distance between global joint positions at the last frame,
//              over joints; averaged over windows.
// Forward kinematics uses each motion's own skeleton.
#pragma once

#include <functional>
#include <cstdint>
#include <string>
#include <vector>

#include "bench/metrics.h"
#include "prior/data/dataset.h"
#include "prior/motion/motion.h"

namespace mf {
class NemfModel;
namespace runtime {
class NemfRuntime;
}
}

namespace mf::bench {

struct ReconMetrics {
  int windows = 0;
  long frames = 0;
  double mre_deg = 0.0;
  double mpe_cm = 0.0;
  double moe_deg = 0.0;
  double mte_cm = 0.0;
  double fde_cm = 0.0;
};

/// Accumulates the reconstruction metrics over windows (see the file comment).
class ReconAccumulator {
 public:
  /// Throws mf::InputError unless both motions have the same frame and joint
  /// counts and at least one frame.
  void add(const Motion& truth, const Motion& pred);
  ReconMetrics summary() const;

 private:
  int windows_ = 0;
  long frames_ = 0, joint_frames_ = 0;
  double rot_sum_ = 0.0, pos_sum_ = 0.0, root_rot_sum_ = 0.0, trans_sum_ = 0.0, fde_sum_ = 0.0;
};

/// Mean joint acceleration (m/s^2): |p(f+1) - 2 p(f) + p(f-1)| * fps^2 of the
/// global joint positions, over frames 1 .. n-2 (those in `frames` when given)
/// and every joint. With `root_relative`, p is the joint's position minus the
/// root's (the root's own term is then 0 and left out), which isolates the
/// pose from the root path. 0 for motions under 3 frames.
double mean_joint_acceleration(const Motion& motion, const std::vector<int>* frames = nullptr,
                               bool root_relative = false);

/// Per joint: the mean local rotation over the training frames (normalised sum
/// of the quaternions taken in the hemisphere of the first one) and a
/// percentile of the angle between each frame's rotation and that mean.
struct JointLimits {
  std::vector<Eigen::Quaterniond> mean;
  std::vector<double> limit_rad;  ///< the percentile angle per joint
  double percentile = 0.999;
};
/// Throws mf::InputError when `clips` is empty or their joint counts differ.
JointLimits compute_joint_limits(const std::vector<Clip>& clips, double percentile = 0.999);

/// Per joint, the number of frames whose local rotation is farther from the
/// mean pose than the limit; add to `exceed` (resized to J) and frames to `frames`.
void count_limit_exceedances(const Motion& motion, const JointLimits& limits, std::vector<long>* exceed,
                             long* frames);

struct PriorEvalOptions {
  int max_windows = 0;                          ///< cap on windows (spread evenly); 0 = all
  std::vector<double> fps_list{30, 60, 120, 240};
  int seam_radius = 5;                          ///< frames from a window boundary that count as "near"
  int samples = 256;                            ///< windows drawn for the sample task
  uint64_t seed = 1;
  /// When set, the sample task hands it every decoded sample window.
  std::function<void(const Motion&)> on_sample;
};

struct ReconResult {
  ReconMetrics full;      ///< windows of exactly the model's length
  ReconMetrics short_;    ///< clips shorter than the model's window (one window each)
  double full_ms = 0.0, short_ms = 0.0;  ///< encode + decode wall time per window
  double skating_cm = 0.0, truth_skating_cm = 0.0;  ///< foot skating over the full windows
  /// Diagnostic: MTE (cm) of the global motion predictor fed the true local
  /// rotations (full windows), separating its error from the decoder's.
  double gmp_on_truth_mte_cm = 0.0;
  int window = 0;
  int threads = 1;
};

/// Encode then decode the validation clips' non-overlapping windows of the
/// model's length (trailing remainders dropped, as NeMF), and separately every
/// clip shorter than the window as one short window: the codec on `runtime`
/// (tasks/latent/prior_codec.h), the GMP on the truth on `model`.
ReconResult run_recon(const NemfModel& model, const runtime::NemfRuntime& runtime, const std::vector<Clip>& clips,
                      const EvalStats& stats, const PriorEvalOptions& options = {});

struct FpsRow {
  double fps = 0.0;
  int windows = 0;
  double accel = 0.0;     ///< mean joint acceleration of the decode (m/s^2)
  double accel_30 = 0.0;  ///< of the decode at 30 fps, same windows
  double truth_30 = 0.0;  ///< of the ground truth at its own rate (30 fps), same windows
  /// The same three, root-relative (the pose without the root path).
  double local = 0.0, local_30 = 0.0, truth_local_30 = 0.0;
  double ms = 0.0;        ///< decode wall time per window
};
struct FpsResult {
  std::vector<FpsRow> rows;
  int threads = 1;
};

/// Encodes the full windows of run_recon once and decodes each at every fps
/// of options.fps_list over the same time span.
FpsResult run_fps(const runtime::NemfRuntime& model, const std::vector<Clip>& clips, const PriorEvalOptions& options = {});

/// Errors of a set of frames of decoded long clips.
struct SeamStats {
  long frames = 0;
  double mre_deg = 0.0;     ///< non-root local rotations
  double mpe_cm = 0.0;      ///< root-relative positions
  double global_cm = 0.0;   ///< global joint positions (includes the root path)
  double accel = 0.0;       ///< mean joint acceleration of the decode (m/s^2)
  double truth_accel = 0.0; ///< of the truth, same frames
  double local = 0.0;       ///< root-relative acceleration of the decode (m/s^2)
  double truth_local = 0.0; ///< of the truth
};
struct SeamResult {
  int clips = 0;
  int windows = 0;
  SeamStats near;       ///< within seam_radius frames of a window's first or last frame (not the clip's ends)
  SeamStats elsewhere;
  double ms_per_window = 0.0;
  int threads = 1;
};

/// Encodes and decodes (30 fps, the clips' rate) every validation clip longer
/// than the model's window through overlapping windows.
SeamResult run_seams(const runtime::NemfRuntime& model, const std::vector<Clip>& clips,
                     const PriorEvalOptions& options = {});

struct SampleResult {
  int samples = 0;
  int truth_windows = 0;
  double skating_cm = 0.0, truth_skating_cm = 0.0;
  /// How much the motions move: mean horizontal root speed (m/s) and mean
  /// root-relative joint acceleration (m/s^2), samples and validation windows.
  double root_speed = 0.0, truth_root_speed = 0.0;
  double local_accel = 0.0, truth_local_accel = 0.0;
  std::vector<std::string> joints;
  std::vector<double> limit_deg;          ///< per joint (root excluded: index 0 unused)
  std::vector<double> sample_fraction;    ///< frames beyond the limit, samples
  std::vector<double> truth_fraction;     ///< frames beyond the limit, validation windows
  double percentile = 0.999;
  double ms_per_window = 0.0;
  int threads = 1;
};

/// Decodes options.samples windows of the model's length from z ~ N(0, I)
/// (fixed seed), root from the global motion predictor, and compares foot
/// skating and joint-limit exceedances with the validation windows of run_recon.
SampleResult run_sample(const NemfModel& model, const std::vector<Clip>& clips, const std::vector<Clip>& train,
                        const EvalStats& stats, const PriorEvalOptions& options = {});

/// Markdown tables (heading, thread count, wall time) of each result.
std::string format_recon(const ReconResult& r);
std::string format_fps(const FpsResult& r);
std::string format_seams(const SeamResult& r, int radius);
std::string format_sample(const SampleResult& r);

}  // namespace mf::bench
