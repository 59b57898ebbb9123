#include "bench/metrics.h"

#include <ATen/ATen.h>

#include "prior/model/representation.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>

#include "prior/data/dataset.h"
#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"

namespace mf::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;

void check_frames(const std::vector<int>& frames, int num_frames, const char* what) {
  for (int f : frames) {
    if (f < 0 || f >= num_frames) {
      std::ostringstream msg;
      msg << what << ": frame " << f << " is out of range [0, " << num_frames << ")";
      throw InputError(msg.str());
    }
  }
}

void check_same_size(const GlobalPose& a, const GlobalPose& b, const char* what) {
  if (a.frames != b.frames || a.joints != b.joints) {
    std::ostringstream msg;
    msg << what << ": truth has " << a.frames << " frames of " << a.joints << " joints, prediction "
        << b.frames << " frames of " << b.joints << " joints";
    throw InputError(msg.str());
  }
}

Eigen::Vector4d wxyz(const Eigen::Quaterniond& q) { return Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()); }

}  // namespace

RigidTransform canonical_transform(const Motion& motion, int anchor_frame, const Eigen::Vector3d& root_forward) {
  if (anchor_frame < 0 || anchor_frame >= motion.num_frames()) {
    std::ostringstream msg;
    msg << "canonicalisation anchor frame " << anchor_frame << " is out of range [0, " << motion.num_frames()
        << ")";
    throw InputError(msg.str());
  }
  const Eigen::Vector3d forward = motion.rotation(anchor_frame, 0) * root_forward;
  double angle = 0.0;
  if (std::hypot(forward.x(), forward.z()) > 1e-9) {
    // R_y(a) maps (cos a, 0, sin a) to +X.
    angle = std::atan2(forward.z(), forward.x());
  }
  RigidTransform t;
  t.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()));
  const Eigen::Vector3d& root = motion.root_positions[anchor_frame];
  t.translation = -(t.rotation * Eigen::Vector3d(root.x(), 0.0, root.z()));
  return t;
}

Motion transform_motion(const Motion& motion, const RigidTransform& transform) {
  Motion out = motion;
  for (int f = 0; f < out.num_frames(); ++f) {
    out.root_positions[f] = transform.apply(motion.root_positions[f]);
    if (out.num_joints() > 0) out.rotation(f, 0) = (transform.rotation * motion.rotation(f, 0)).normalized();
  }
  return out;
}

Motion canonicalise(const Motion& motion, int anchor_frame, const Eigen::Vector3d& root_forward) {
  return transform_motion(motion, canonical_transform(motion, anchor_frame, root_forward));
}

std::vector<FootJoint> metric_foot_joints(const Skeleton& skeleton) {
  std::vector<bool> is_toe;
  const std::vector<int> joints = find_foot_joints(skeleton, &is_toe);
  std::vector<FootJoint> feet;
  for (size_t k = 0; k < joints.size(); ++k) feet.push_back({joints[k], is_toe[k] ? 4.0 : 8.0});
  std::sort(feet.begin(), feet.end(), [](const FootJoint& a, const FootJoint& b) { return a.joint < b.joint; });
  return feet;
}

double quantile(std::vector<double> values, double q) {
  if (values.empty()) throw InputError("quantile of an empty set");
  std::sort(values.begin(), values.end());
  const double pos = std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(lo + 1, values.size() - 1);
  const double frac = pos - static_cast<double>(lo);
  return values[lo] + (values[hi] - values[lo]) * frac;
}

EvalStats compute_eval_stats(const std::vector<Clip>& train, const EvalStatsOptions& options) {
  if (train.empty()) throw InputError("evaluation statistics need at least one training clip");
  if (options.window_length < 1 || options.window_stride < 1 || options.anchor_frame < 0 ||
      options.anchor_frame >= options.window_length) {
    throw InputError("evaluation statistics: bad window length, stride or anchor frame");
  }
  const Skeleton& skeleton = train.front().motion.skeleton;
  const int J = skeleton.num_joints();
  EvalStats stats;
  stats.joint_names = skeleton.names;
  stats.feet = metric_foot_joints(skeleton);

  const int D = 3 * J;
  std::vector<double> sum(D, 0.0), sum_sq(D, 0.0);
  long samples = 0;
  std::vector<std::vector<double>> foot_quantiles(stats.feet.size());
  for (const Clip& clip : train) {
    const Motion& m = clip.motion;
    if (m.num_joints() != J) {
      std::ostringstream msg;
      msg << "evaluation statistics: clip " << clip.name << " has " << m.num_joints() << " joints, expected " << J;
      throw InputError(msg.str());
    }
    if (m.num_frames() == 0) continue;
    // Standing heights: heights do not depend on the canonicalisation.
    const GlobalPose whole = forward_kinematics(m);
    for (size_t i = 0; i < stats.feet.size(); ++i) {
      std::vector<double> heights(m.num_frames());
      for (int f = 0; f < m.num_frames(); ++f) heights[f] = whole.position(f, stats.feet[i].joint).y();
      foot_quantiles[i].push_back(quantile(std::move(heights), 0.05));
    }
    ++stats.clips;
    for (int start = 0; start + options.window_length <= m.num_frames(); start += options.window_stride) {
      const Motion window = canonicalise(m.slice(start, start + options.window_length), options.anchor_frame,
                                         options.root_forward);
      const GlobalPose pose = forward_kinematics(window);
      for (int f = 0; f < pose.frames; ++f) {
        for (int j = 0; j < J; ++j) {
          const Eigen::Vector3d& p = pose.position(f, j);
          for (int a = 0; a < 3; ++a) {
            sum[3 * j + a] += p[a];
            sum_sq[3 * j + a] += p[a] * p[a];
          }
        }
      }
      samples += pose.frames;
      ++stats.windows;
    }
  }
  if (stats.windows == 0) {
    std::ostringstream msg;
    msg << "evaluation statistics: no training clip has " << options.window_length << " frames";
    throw InputError(msg.str());
  }
  stats.position_mean.resize(D);
  stats.position_std.resize(D);
  for (int d = 0; d < D; ++d) {
    const double mean = sum[d] / samples;
    const double var = std::max(0.0, sum_sq[d] / samples - mean * mean);
    stats.position_mean[d] = mean;
    stats.position_std[d] = std::max(std::sqrt(var), kMinStd);
  }
  for (auto& q : foot_quantiles) stats.standing_height.push_back(quantile(q, 0.5));
  return stats;
}

std::vector<double> continuous_quaternions(const GlobalPose& pose, const GlobalPose* reference) {
  const int J = pose.joints;
  if (reference && (reference->joints != J || reference->frames < 1)) {
    throw InputError("continuous_quaternions: the reference has a different joint count or no frame");
  }
  std::vector<double> out(static_cast<size_t>(pose.frames) * J * 4);
  for (int j = 0; j < J; ++j) {
    Eigen::Vector4d prev;
    for (int f = 0; f < pose.frames; ++f) {
      Eigen::Vector4d q = wxyz(pose.rotation(f, j));
      if (f == 0) {
        double side = q[0];
        if (reference) {
          // The hemisphere continuous_quaternions(*reference) gives its frame 0.
          Eigen::Vector4d r = wxyz(reference->rotation(0, j));
          if (r[0] < 0.0) r = -r;
          side = q.dot(r);
        }
        if (side < 0.0) q = -q;
      } else if (q.dot(prev) < 0.0) {
        q = -q;
      }
      prev = q;
      for (int c = 0; c < 4; ++c) out[(static_cast<size_t>(f) * J + j) * 4 + c] = q[c];
    }
  }
  return out;
}

double l2p(const GlobalPose& truth, const GlobalPose& pred, const std::vector<int>& frames, const EvalStats& stats,
           L2PAxes axes) {
  check_same_size(truth, pred, "L2P");
  check_frames(frames, truth.frames, "L2P");
  if (static_cast<int>(stats.position_std.size()) != 3 * truth.joints) {
    throw InputError("L2P: the statistics belong to a skeleton with another joint count");
  }
  if (frames.empty()) return 0.0;
  double total = 0.0;
  for (int f : frames) {
    double sq = 0.0;
    for (int j = 0; j < truth.joints; ++j) {
      const Eigen::Vector3d d = pred.position(f, j) - truth.position(f, j);
      for (int a = 0; a < 3; ++a) {
        if ((axes == L2PAxes::Horizontal && a == 1) || (axes == L2PAxes::Vertical && a != 1)) continue;
        const double z = d[a] / stats.position_std[3 * j + a];  // the means cancel
        sq += z * z;
      }
    }
    total += std::sqrt(sq);
  }
  return total / frames.size();
}

double l2q(const std::vector<double>& truth_quats, const std::vector<double>& pred_quats, int joints,
           const std::vector<int>& frames) {
  if (truth_quats.size() != pred_quats.size() || joints < 1 || truth_quats.size() % (4 * joints) != 0) {
    throw InputError("L2Q: truth and prediction quaternions differ in size");
  }
  const int num_frames = static_cast<int>(truth_quats.size() / (4 * joints));
  check_frames(frames, num_frames, "L2Q");
  if (frames.empty()) return 0.0;
  double total = 0.0;
  for (int f : frames) {
    double sq = 0.0;
    const size_t base = static_cast<size_t>(f) * joints * 4;
    for (int c = 0; c < joints * 4; ++c) {
      const double d = pred_quats[base + c] - truth_quats[base + c];
      sq += d * d;
    }
    total += std::sqrt(sq);
  }
  return total / frames.size();
}

NpssTerms npss_terms(const std::vector<double>& truth, const std::vector<double>& pred, int channels) {
  if (channels < 1 || truth.size() != pred.size() || truth.size() % channels != 0) {
    throw InputError("NPSS: truth and prediction differ in size");
  }
  const int T = static_cast<int>(truth.size() / channels);
  NpssTerms terms;
  if (T == 0) return terms;
  // Real part of the DFT: Re X_k = sum_t x_t cos(2 pi k t / T).
  std::vector<double> cosines(static_cast<size_t>(T) * T);
  for (int k = 0; k < T; ++k) {
    for (int t = 0; t < T; ++t) cosines[static_cast<size_t>(k) * T + t] = std::cos(2.0 * kPi * ((static_cast<long>(k) * t) % T) / T);
  }
  std::vector<double> pt(T), pp(T);
  for (int c = 0; c < channels; ++c) {
    double total_t = 0.0, total_p = 0.0;
    for (int k = 0; k < T; ++k) {
      double rt = 0.0, rp = 0.0;
      for (int t = 0; t < T; ++t) {
        const double w = cosines[static_cast<size_t>(k) * T + t];
        rt += w * truth[static_cast<size_t>(t) * channels + c];
        rp += w * pred[static_cast<size_t>(t) * channels + c];
      }
      pt[k] = rt * rt;
      pp[k] = rp * rp;
      total_t += pt[k];
      total_p += pp[k];
    }
    if (total_t <= 0.0) continue;  // zero weight
    double cdf_t = 0.0, cdf_p = 0.0, emd = 0.0;
    for (int k = 0; k < T; ++k) {
      cdf_t += pt[k] / total_t;
      cdf_p += total_p > 0.0 ? pp[k] / total_p : 0.0;
      emd += std::abs(cdf_p - cdf_t);
    }
    terms.weighted_emd += total_t * emd;
    terms.weight += total_t;
  }
  return terms;
}

double mpjpe_cm(const GlobalPose& truth, const GlobalPose& pred, const std::vector<int>& frames) {
  check_same_size(truth, pred, "MPJPE");
  check_frames(frames, truth.frames, "MPJPE");
  if (frames.empty() || truth.joints == 0) return 0.0;
  double total = 0.0;
  for (int f : frames) {
    for (int j = 0; j < truth.joints; ++j) total += (pred.position(f, j) - truth.position(f, j)).norm();
  }
  return 100.0 * total / (static_cast<double>(frames.size()) * truth.joints);
}

double contact_weight(double height_cm, double threshold_cm) {
  return std::clamp(2.0 - std::pow(2.0, height_cm / threshold_cm), 0.0, 1.0);
}

SkatingTerms foot_skating(const GlobalPose& pose, const std::vector<int>& frames, const std::vector<FootJoint>& feet,
                          const std::vector<double>& standing_height) {
  check_frames(frames, pose.frames, "foot skating");
  if (feet.size() != standing_height.size()) throw InputError("foot skating: one standing height per foot joint");
  SkatingTerms terms;
  for (int f : frames) {
    if (f == 0) continue;
    for (size_t i = 0; i < feet.size(); ++i) {
      const int j = feet[i].joint;
      if (j < 0 || j >= pose.joints) throw InputError("foot skating: foot joint out of range");
      const Eigen::Vector3d& p = pose.position(f, j);
      const Eigen::Vector3d& q = pose.position(f - 1, j);
      const double displacement_cm = 100.0 * std::hypot(p.x() - q.x(), p.z() - q.z());
      const double h_cm = 100.0 * (p.y() - standing_height[i]);
      terms.sum_cm += displacement_cm * contact_weight(h_cm, feet[i].threshold_cm);
      ++terms.count;
    }
  }
  return terms;
}

void KnownFrameError::merge(const KnownFrameError& other) {
  position_max_cm = std::max(position_max_cm, other.position_max_cm);
  rotation_max_deg = std::max(rotation_max_deg, other.rotation_max_deg);
  position_sum_cm += other.position_sum_cm;
  rotation_sum_deg += other.rotation_sum_deg;
  count += other.count;
}

KnownFrameError known_frame_error(const Motion& truth, const GlobalPose& truth_pose, const Motion& pred,
                                  const GlobalPose& pred_pose, const std::vector<int>& frames) {
  check_same_size(truth_pose, pred_pose, "known-frame error");
  if (truth.num_frames() != truth_pose.frames || pred.num_frames() != pred_pose.frames ||
      truth.num_joints() != truth_pose.joints || pred.num_joints() != pred_pose.joints) {
    throw InputError("known-frame error: motions and poses disagree in size");
  }
  check_frames(frames, truth.num_frames(), "known-frame error");
  KnownFrameError e;
  for (int f : frames) {
    for (int j = 0; j < truth.num_joints(); ++j) {
      const double p = 100.0 * (pred_pose.position(f, j) - truth_pose.position(f, j)).norm();
      const double r = geodesic_angle(truth.rotation(f, j), pred.rotation(f, j)) * 180.0 / kPi;
      e.position_max_cm = std::max(e.position_max_cm, p);
      e.rotation_max_deg = std::max(e.rotation_max_deg, r);
      e.position_sum_cm += p;
      e.rotation_sum_deg += r;
      ++e.count;
    }
  }
  return e;
}

double l2t(const Motion& truth, const Motion& pred, const std::vector<int>& evaluated,
           const Eigen::Vector3d& root_forward) {
  check_frames(evaluated, truth.num_frames(), "l2t");
  check_frames(evaluated, pred.num_frames(), "l2t");
  if (evaluated.empty()) throw InputError("l2t: no evaluated frame");
  auto features = [&](const Motion& m) {
    const int64_t n = static_cast<int64_t>(evaluated.size());
    at::Tensor r = at::empty({n, 3, 3}, at::kDouble), p = at::empty({n, 3}, at::kDouble);
    auto ra = r.accessor<double, 3>();
    auto pa = p.accessor<double, 2>();
    for (int64_t i = 0; i < n; ++i) {
      const int f = evaluated[static_cast<size_t>(i)];
      const Eigen::Matrix3d q = m.rotation(f, 0).normalized().toRotationMatrix();
      for (int a = 0; a < 3; ++a) {
        pa[i][a] = m.root_positions[f][a];
        for (int b = 0; b < 3; ++b) ra[i][a][b] = q(a, b);
      }
    }
    return trajectory_features(r, p, root_forward);
  };
  return (features(truth) - features(pred)).norm(2, -1).mean().item<double>();
}

void MetricAccumulator::add(const Motion& truth, const Motion& pred, const std::vector<int>& evaluated,
                            const std::vector<int>& known) {
  if (truth.num_frames() != pred.num_frames() || truth.num_joints() != pred.num_joints()) {
    std::ostringstream msg;
    msg << "metrics: the prediction has " << pred.num_frames() << " frames of " << pred.num_joints()
        << " joints, the truth " << truth.num_frames() << " frames of " << truth.num_joints() << " joints";
    throw InputError(msg.str());
  }
  if (truth.skeleton.names != stats_.joint_names) {
    throw InputError("metrics: the evaluation statistics belong to another skeleton");
  }
  if (evaluated.empty()) throw InputError("metrics: no evaluated frame");
  check_frames(evaluated, truth.num_frames(), "metrics");
  check_frames(known, truth.num_frames(), "metrics");

  const GlobalPose tp = forward_kinematics(truth);
  const GlobalPose pp = forward_kinematics(pred);
  const int J = truth.num_joints();
  const long n = static_cast<long>(evaluated.size());

  l2p_sum_ += l2p(tp, pp, evaluated, stats_) * n;
  l2p_h_sum_ += l2p(tp, pp, evaluated, stats_, L2PAxes::Horizontal) * n;
  l2p_v_sum_ += l2p(tp, pp, evaluated, stats_, L2PAxes::Vertical) * n;
  mpjpe_sum_ += mpjpe_cm(tp, pp, evaluated) * n;
  l2t_sum_ += l2t(truth, pred, evaluated, root_forward_) * n;

  const std::vector<double> tq = continuous_quaternions(tp);
  const std::vector<double> pq = continuous_quaternions(pp, &tp);
  l2q_sum_ += l2q(tq, pq, J, evaluated) * n;

  std::vector<double> ts, ps;
  ts.reserve(evaluated.size() * J * 4);
  ps.reserve(evaluated.size() * J * 4);
  for (int f : evaluated) {
    const size_t base = static_cast<size_t>(f) * J * 4;
    ts.insert(ts.end(), tq.begin() + base, tq.begin() + base + J * 4);
    ps.insert(ps.end(), pq.begin() + base, pq.begin() + base + J * 4);
  }
  const NpssTerms npss = npss_terms(ts, ps, J * 4);
  npss_.weighted_emd += npss.weighted_emd;
  npss_.weight += npss.weight;

  const SkatingTerms sp = foot_skating(pp, evaluated, stats_.feet, stats_.standing_height);
  const SkatingTerms st = foot_skating(tp, evaluated, stats_.feet, stats_.standing_height);
  skate_pred_.sum_cm += sp.sum_cm;
  skate_pred_.count += sp.count;
  skate_truth_.sum_cm += st.sum_cm;
  skate_truth_.count += st.count;

  known_.merge(known_frame_error(truth, tp, pred, pp, known));
  frames_ += n;
  ++windows_;
}

MetricSummary MetricAccumulator::summary() const {
  MetricSummary s;
  s.windows = windows_;
  if (frames_ > 0) {
    s.l2p = l2p_sum_ / frames_;
    s.l2p_horizontal = l2p_h_sum_ / frames_;
    s.l2p_vertical = l2p_v_sum_ / frames_;
    s.l2q = l2q_sum_ / frames_;
    s.l2t = l2t_sum_ / frames_;
    s.mpjpe_cm = mpjpe_sum_ / frames_;
  }
  s.npss = npss_.value();
  s.skating_cm = skate_pred_.value();
  s.truth_skating_cm = skate_truth_.value();
  s.known = known_;
  return s;
}

}  // namespace mf::bench
