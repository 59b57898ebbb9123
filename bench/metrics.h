// Evaluation metrics of the benchmark (motionfield-bench, docs/BENCHMARKS.md):
// the LaFAN1 metrics (L2P, L2Q, NPSS), MPJPE, foot skating and the error on
// known frames, plus the canonicalisation every window goes through first.
//
// All functions take motions in the internal units (metres, Y-up, see
// prior/motion/skeleton.h) and report the units named in their documentation
// (centimetres and degrees where a unit is named; L2P, L2Q and NPSS are
// unitless).
//
// Definitions, and where they differ from the papers:
//
// * Canonicalisation (LaFAN1, Qin et al.): a rigid transform made of a
//   translation that puts the root's ground position (x, z) at an anchor frame at
//   the origin and a rotation about +Y that makes the root face +X at that
//   frame. The facing is the root's local forward axis (a parameter; +Z on the
//   Bandai Namco rig, whose Hips' local +Z points forward) rotated into the world
//   and projected onto the ground. LaFAN1 centres on the mean root ground
//   position of the window instead; we centre on the anchor frame, as the
//   transformer papers do. The transform is computed from the ground truth and
//   applied to truth and prediction alike.
//
// * L2P (LaFAN1): global joint positions of a frame, all joints' xyz flattened,
//   z-scored per coordinate with the mean and standard deviation of the training
//   split (EvalStats), L2 norm of the difference between truth and prediction;
//   mean over windows and evaluated frames.
//
// * L2Q (LaFAN1): the same on global quaternions (w, x, y, z per joint,
//   flattened), not z-scored. Signs are made continuous over time within each
//   window (each frame takes the sign closer to the previous frame's) and the
//   prediction's first frame takes, per joint, the hemisphere of the truth's
//   first frame, so that L2Q never counts a sign flip as an error.
//
// * NPSS (LaFAN1's fast_npss): per window and channel (the J * 4 global
//   quaternion components, signs as for L2Q) over the evaluated frames: the real
//   part of the DFT over time, squared (power), divided by the channel's total
//   power, summed cumulatively over frequency; the L1 distance between the
//   cumulative spectra of truth and prediction. The result is the average over
//   every (window, channel) pair weighted by the truth's total power of that
//   pair. A channel whose total power is zero has a zero normalised spectrum
//   (numpy would produce NaN there); with zero truth power it has zero weight.
//
// * MPJPE (cm): mean Euclidean distance between predicted and true global joint
//   positions over evaluated frames and all joints, in centimetres.
//
// * Foot skating (cm), NeMF's definition adapted to this rig. NeMF weighs the
//   horizontal displacement of each foot joint from the previous frame by
//   clamp(2 - 2^(h / H), 0, 1), with h the joint's height above the floor and H =
//   8 cm for ankles and 4 cm for toes. On the Bandai Namco rig the feet stand
//   high (standing ankle about 11.7 cm and toe about 4.3 cm above the floor), so
//   absolute heights never count as contact. Adaptation: h is the height above
//   that joint's *standing height*, measured on the training split as the median
//   over training clips of the joint's 5th-percentile height within the clip
//   (EvalStats::standing_height). Foot joints are those whose name contains
//   "toe" (toe, H = 4 cm) or else "foot" or "ankle" (ankle, H = 8 cm),
//   case-insensitive: Foot_L, Foot_R, Toes_L, Toes_R on the data rig. h is taken
//   at the frame whose displacement is measured (frame f, displacement f-1 -> f).
//   The result is the mean over evaluated frames (those with a previous frame)
//   and foot joints, in centimetres; skating of the ground truth over the same
//   frames is the reference the data itself reaches.
//
// * Known-frame error: over the known frames, the maximum and the mean of the
//   global joint position error (cm, over joints and frames) and of the local
//   rotation geodesic error (degrees, every joint including the root). A method
//   that keeps its known frames scores about 0 on both.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "prior/motion/motion.h"

namespace mf {
struct Clip;
}

namespace mf::bench {

/// A rigid transform of the world made of a rotation about +Y and a
/// translation: p' = rotation * p + translation.
struct RigidTransform {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Vector3d apply(const Eigen::Vector3d& p) const { return rotation * p + translation; }
};

/// The canonicalising transform of `motion` at `anchor_frame`: afterwards the
/// root's ground position at that frame is (0, y, 0) (its height is kept) and
/// the ground projection of `root_forward` (the root's forward axis in its own
/// local frame) points to +X. If the forward axis is vertical at the anchor
/// frame, no rotation is applied. Throws mf::InputError if anchor_frame is out
/// of range.
RigidTransform canonical_transform(const Motion& motion, int anchor_frame,
                                   const Eigen::Vector3d& root_forward = Eigen::Vector3d::UnitZ());

/// `motion` with the transform applied to its root translation and rotation (so
/// to every global pose); local rotations of the other joints are unchanged.
Motion transform_motion(const Motion& motion, const RigidTransform& transform);

/// transform_motion(motion, canonical_transform(motion, anchor_frame, root_forward)).
Motion canonicalise(const Motion& motion, int anchor_frame,
                    const Eigen::Vector3d& root_forward = Eigen::Vector3d::UnitZ());

/// A foot joint and its NeMF contact threshold.
struct FootJoint {
  int joint = -1;
  double threshold_cm = 8.0;  ///< 8 for ankles, 4 for toes
};

/// The foot joints of a skeleton by name (mf::find_foot_joints, see the file
/// comment) with their contact thresholds, in index order.
std::vector<FootJoint> metric_foot_joints(const Skeleton& skeleton);

/// Statistics of the training split the metrics need.
struct EvalStats {
  std::vector<std::string> joint_names;  ///< the skeleton the statistics belong to
  /// Mean and standard deviation of each canonicalised global position
  /// coordinate (joint-major: 3 * j + axis), metres; std floored at kMinStd.
  std::vector<double> position_mean;
  std::vector<double> position_std;
  std::vector<FootJoint> feet;
  /// Standing height (global y, metres) of each foot joint, parallel to `feet`.
  std::vector<double> standing_height;
  int windows = 0;  ///< training windows the position statistics come from
  int clips = 0;    ///< training clips the standing heights come from
};

constexpr double kMinStd = 1e-8;

struct EvalStatsOptions {
  int window_length = 50;
  int window_stride = 20;
  int anchor_frame = 9;  ///< the last context frame of a 10-frame context
  Eigen::Vector3d root_forward = Eigen::Vector3d::UnitZ();
};

/// Computes EvalStats from training clips: position statistics over windows
/// of window_length frames every window_stride frames (only windows that fit
/// in their clip), each canonicalised at anchor_frame; standing heights as the
/// median over clips of each foot joint's 5th-percentile height (linear
/// interpolation between order statistics, like numpy's default; the median of
/// an even count averages the two middle values). Throws mf::InputError if no
/// clip is given, the clips' skeletons differ in joint count, or no window fits.
EvalStats compute_eval_stats(const std::vector<Clip>& train, const EvalStatsOptions& options = {});

/// The q-th quantile (q in [0, 1]) of `values` with linear interpolation, as
/// numpy.percentile(values, 100 q). Throws mf::InputError on an empty input.
double quantile(std::vector<double> values, double q);

/// Global quaternions of every frame as (w, x, y, z) channels, frame-major:
/// out[(f * J + j) * 4 + c]. Signs are continuous over time; when `reference`
/// is given (same joint count, at least one frame), frame 0 of each joint takes
/// the hemisphere that continuous_quaternions(*reference) gives reference's
/// frame 0 (so truth and prediction agree), otherwise the hemisphere w >= 0.
std::vector<double> continuous_quaternions(const GlobalPose& pose, const GlobalPose* reference = nullptr);

// ---------------------------------------------------------------------------
// Per-window metrics. `frames` lists the evaluated frames (each in range);
// truth and prediction must have the same frame and joint counts (else
// mf::InputError). Positions in metres as produced by forward_kinematics.

/// Which coordinates L2P sums: all (the metric), or only the horizontal (x, z)
/// or vertical (y) ones (a diagnostic: on upright data the vertical standard
/// deviations are small and the vertical part can dominate).
enum class L2PAxes { All, Horizontal, Vertical };

/// Mean over `frames` of the L2 norm of the z-scored position difference.
double l2p(const GlobalPose& truth, const GlobalPose& pred, const std::vector<int>& frames, const EvalStats& stats,
           L2PAxes axes = L2PAxes::All);

/// Mean over `frames` of the L2 norm of the difference of the global quaternion
/// channels; both given as continuous_quaternions() output for `joints` joints.
double l2q(const std::vector<double>& truth_quats, const std::vector<double>& pred_quats, int joints,
           const std::vector<int>& frames);

/// Sums for NPSS: sum over channels of weight * emd, and sum of weights. The
/// NPSS of a set of windows is the ratio of the sums of both over the set.
struct NpssTerms {
  double weighted_emd = 0.0;
  double weight = 0.0;
  double value() const { return weight > 0.0 ? weighted_emd / weight : 0.0; }
};

/// NPSS terms of one window. `truth` and `pred` are time series frame-major
/// with `channels` values per frame (series[t * channels + c]) and the same
/// length (the evaluated frames only).
NpssTerms npss_terms(const std::vector<double>& truth, const std::vector<double>& pred, int channels);

/// Mean Euclidean distance (cm) over `frames` and every joint.
double mpjpe_cm(const GlobalPose& truth, const GlobalPose& pred, const std::vector<int>& frames);

/// Foot skating (cm) of one motion: sum and count of the terms (frame, foot
/// joint) over `frames`; frames without a previous frame (frame 0) are skipped.
/// `feet` and `standing_height` (metres) as in EvalStats.
struct SkatingTerms {
  double sum_cm = 0.0;
  long count = 0;
  double value() const { return count > 0 ? sum_cm / count : 0.0; }
};
SkatingTerms foot_skating(const GlobalPose& pose, const std::vector<int>& frames, const std::vector<FootJoint>& feet,
                          const std::vector<double>& standing_height);

/// NeMF's contact weight clamp(2 - 2^(h / threshold), 0, 1).
double contact_weight(double height_cm, double threshold_cm);

/// Error on known frames: position error in cm over joints and frames, local
/// rotation geodesic error in degrees over joints and frames.
struct KnownFrameError {
  double position_max_cm = 0.0;
  double position_sum_cm = 0.0;
  double rotation_max_deg = 0.0;
  double rotation_sum_deg = 0.0;
  long count = 0;  ///< joint-frame pairs
  double position_mean_cm() const { return count > 0 ? position_sum_cm / count : 0.0; }
  double rotation_mean_deg() const { return count > 0 ? rotation_sum_deg / count : 0.0; }
  void merge(const KnownFrameError& other);
};
KnownFrameError known_frame_error(const Motion& truth, const GlobalPose& truth_pose, const Motion& pred,
                                  const GlobalPose& pred_pose, const std::vector<int>& frames);

// ---------------------------------------------------------------------------
// Aggregation over windows.

/// The metrics of a set of windows.
struct MetricSummary {
  int windows = 0;
  double l2p = 0.0;
  double l2p_horizontal = 0.0;  ///< L2P over x and z only (diagnostic)
  double l2p_vertical = 0.0;    ///< L2P over y only (diagnostic)
  double l2q = 0.0;
  double npss = 0.0;
  double mpjpe_cm = 0.0;
  double skating_cm = 0.0;        ///< of the prediction
  double truth_skating_cm = 0.0;  ///< of the ground truth, same frames
  double l2t = 0.0;               ///< l2t() over the evaluated frames
  KnownFrameError known;
};

/// L2T: the mean over `evaluated` frames of the L2 distance between the
/// trajectory features of truth and prediction (both in the same canonical
/// frame): root ground x, z in metres and the unit facing vector (forward_x,
/// forward_z) of the root's heading (trajectory_features() of
/// prior/model/representation.h; `root_forward` the root-local forward axis).
double l2t(const Motion& truth, const Motion& pred, const std::vector<int>& evaluated,
           const Eigen::Vector3d& root_forward);

/// Adds windows one at a time and summarises them. L2P, L2Q and MPJPE are means
/// over every evaluated (window, frame) pair, skating over every (window, frame,
/// foot) term, NPSS the power-weighted mean over every (window, channel) pair.
/// Keeps a reference to `stats`, which must outlive it.
class MetricAccumulator {
 public:
  /// `root_forward`: the root-local forward axis, for L2T.
  explicit MetricAccumulator(const EvalStats& stats, const Eigen::Vector3d& root_forward = Eigen::Vector3d::UnitZ())
      : stats_(stats), root_forward_(root_forward) {}

  /// `truth` and `pred` are already in the same (canonical) frame; metrics are
  /// taken over `evaluated` frames, the known-frame error over `known` frames.
  /// Throws mf::InputError if the motions disagree in size or skeleton, a frame
  /// is out of range, `evaluated` is empty, or the stats belong to another
  /// skeleton.
  void add(const Motion& truth, const Motion& pred, const std::vector<int>& evaluated, const std::vector<int>& known);

  MetricSummary summary() const;

 private:
  const EvalStats& stats_;
  Eigen::Vector3d root_forward_;
  int windows_ = 0;
  double l2t_sum_ = 0.0;
  double l2p_sum_ = 0.0, l2p_h_sum_ = 0.0, l2p_v_sum_ = 0.0, l2q_sum_ = 0.0, mpjpe_sum_ = 0.0;
  long frames_ = 0;
  NpssTerms npss_;
  SkatingTerms skate_pred_, skate_truth_;
  KnownFrameError known_;
};

}  // namespace mf::bench
