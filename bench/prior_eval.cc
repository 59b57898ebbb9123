#include "bench/prior_eval.h"

#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <torch/types.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <sstream>

#include "bench/protocol.h"
#include "bench/text.h"
#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "prior/motion/rotations_torch.h"
#include "prior/runtime/nemf_runtime.h"
#include "tasks/latent/prior_codec.h"

namespace mf::bench {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kRadToDeg = 57.29577951308232;

// Full windows of `length` frames (non-overlapping) and, separately, clips shorter than `length`.
void recon_windows(const std::vector<Clip>& clips, int length, int max_windows, std::vector<Window>* full,
                   std::vector<Window>* short_clips) {
  std::vector<Window> all = make_windows(clips, length, length, true);
  for (const Window& w : all) (w.length == length ? full : short_clips)->push_back(w);
  *full = cap_windows(*full, max_windows);
  *short_clips = cap_windows(*short_clips, max_windows);
}

Motion window_motion(const std::vector<Clip>& clips, const Window& w) {
  return clips[w.clip].motion.slice(w.start, w.start + w.length);
}

// Per-frame error terms of a decoded long clip, summed into `s`.
void add_frame_errors(const Motion& truth, const GlobalPose& tp, const Motion& pred, const GlobalPose& pp, int f,
                      SeamStats* s, long* joint_frames) {
  const int J = truth.num_joints();
  for (int j = 1; j < J; ++j) {
    s->mre_deg += geodesic_angle(truth.rotation(f, j), pred.rotation(f, j)) * kRadToDeg;
    const Eigen::Vector3d rt = tp.position(f, j) - tp.position(f, 0);
    const Eigen::Vector3d rp = pp.position(f, j) - pp.position(f, 0);
    s->mpe_cm += 100.0 * (rt - rp).norm();
  }
  for (int j = 0; j < J; ++j) s->global_cm += 100.0 * (tp.position(f, j) - pp.position(f, j)).norm();
  *joint_frames += 1;
}

// Mean horizontal root speed (m/s) over the frame steps of a motion.
double root_speed(const Motion& m) {
  if (m.num_frames() < 2) return 0.0;
  double sum = 0.0;
  for (int f = 1; f < m.num_frames(); ++f) {
    const Eigen::Vector3d d = m.root_positions[f] - m.root_positions[f - 1];
    sum += std::hypot(d.x(), d.z()) * m.fps;
  }
  return sum / (m.num_frames() - 1);
}

// Sum over joints of |second difference| * fps^2 at frame f; root-relative
// positions skip the root (its term is zero).
double accel_sum(const GlobalPose& p, int f, double fps, bool root_relative) {
  double sum = 0.0;
  const Eigen::Vector3d r = root_relative ? Eigen::Vector3d(p.position(f + 1, 0) - 2.0 * p.position(f, 0) +
                                                            p.position(f - 1, 0))
                                          : Eigen::Vector3d::Zero();
  for (int j = root_relative ? 1 : 0; j < p.joints; ++j) {
    sum += (p.position(f + 1, j) - 2.0 * p.position(f, j) + p.position(f - 1, j) - r).norm() * fps * fps;
  }
  return sum;
}

}  // namespace

void ReconAccumulator::add(const Motion& truth, const Motion& pred) {
  const int T = truth.num_frames(), J = truth.num_joints();
  if (T < 1 || pred.num_frames() != T || pred.num_joints() != J) {
    throw InputError("reconstruction metrics need two motions of the same, non-zero size");
  }
  const GlobalPose tp = forward_kinematics(truth), pp = forward_kinematics(pred);
  for (int f = 0; f < T; ++f) {
    for (int j = 1; j < J; ++j) {
      rot_sum_ += geodesic_angle(truth.rotation(f, j), pred.rotation(f, j)) * kRadToDeg;
      const Eigen::Vector3d rt = tp.position(f, j) - tp.position(f, 0);
      const Eigen::Vector3d rp = pp.position(f, j) - pp.position(f, 0);
      pos_sum_ += 100.0 * (rt - rp).norm();
    }
    root_rot_sum_ += geodesic_angle(truth.rotation(f, 0), pred.rotation(f, 0)) * kRadToDeg;
    trans_sum_ += 100.0 * (truth.root_positions[f] - pred.root_positions[f]).norm();
  }
  double fde = 0.0;
  for (int j = 0; j < J; ++j) fde += 100.0 * (tp.position(T - 1, j) - pp.position(T - 1, j)).norm();
  fde_sum_ += fde / J;
  frames_ += T;
  joint_frames_ += static_cast<long>(T) * (J - 1);
  ++windows_;
}

ReconMetrics ReconAccumulator::summary() const {
  ReconMetrics m;
  m.windows = windows_;
  m.frames = frames_;
  if (windows_ == 0) return m;
  if (joint_frames_ > 0) {
    m.mre_deg = rot_sum_ / joint_frames_;
    m.mpe_cm = pos_sum_ / joint_frames_;
  }
  m.moe_deg = root_rot_sum_ / frames_;
  m.mte_cm = trans_sum_ / frames_;
  m.fde_cm = fde_sum_ / windows_;
  return m;
}

double mean_joint_acceleration(const Motion& motion, const std::vector<int>* frames, bool root_relative) {
  const int T = motion.num_frames();
  if (T < 3 || (root_relative && motion.num_joints() < 2)) return 0.0;
  const GlobalPose p = forward_kinematics(motion);
  double sum = 0.0;
  long n = 0;
  auto add = [&](int f) {
    if (f < 1 || f > T - 2) return;
    sum += accel_sum(p, f, motion.fps, root_relative);
    n += root_relative ? p.joints - 1 : p.joints;
  };
  if (frames) {
    for (int f : *frames) add(f);
  } else {
    for (int f = 1; f < T - 1; ++f) add(f);
  }
  return n > 0 ? sum / n : 0.0;
}

JointLimits compute_joint_limits(const std::vector<Clip>& clips, double percentile) {
  if (clips.empty()) throw InputError("joint limits need at least one clip");
  const int J = clips.front().motion.num_joints();
  JointLimits lim;
  lim.percentile = percentile;
  std::vector<Eigen::Vector4d> sum(J, Eigen::Vector4d::Zero());
  std::vector<Eigen::Vector4d> ref(J);
  for (int j = 0; j < J; ++j) ref[j] = clips.front().motion.rotation(0, j).normalized().coeffs();
  for (const Clip& c : clips) {
    if (c.motion.num_joints() != J) throw InputError("joint limits: clips with different joint counts");
    for (int f = 0; f < c.motion.num_frames(); ++f) {
      for (int j = 0; j < J; ++j) {
        Eigen::Vector4d q = c.motion.rotation(f, j).normalized().coeffs();
        sum[j] += q.dot(ref[j]) < 0 ? -q : q;
      }
    }
  }
  lim.mean.resize(J);
  lim.limit_rad.assign(J, 0.0);
  for (int j = 0; j < J; ++j) {
    Eigen::Vector4d m = sum[j].normalized();
    lim.mean[j] = Eigen::Quaterniond(m[3], m[0], m[1], m[2]);  // coeffs() is (x, y, z, w)
  }
  std::vector<std::vector<double>> angles(J);
  for (const Clip& c : clips) {
    for (int f = 0; f < c.motion.num_frames(); ++f) {
      for (int j = 0; j < J; ++j) angles[j].push_back(geodesic_angle(c.motion.rotation(f, j), lim.mean[j]));
    }
  }
  for (int j = 0; j < J; ++j) lim.limit_rad[j] = quantile(std::move(angles[j]), percentile);
  return lim;
}

void count_limit_exceedances(const Motion& motion, const JointLimits& limits, std::vector<long>* exceed,
                             long* frames) {
  const int J = motion.num_joints();
  if (static_cast<int>(limits.mean.size()) != J) throw InputError("joint limits belong to another skeleton");
  exceed->resize(J, 0);
  for (int f = 0; f < motion.num_frames(); ++f) {
    for (int j = 0; j < J; ++j) {
      if (geodesic_angle(motion.rotation(f, j), limits.mean[j]) > limits.limit_rad[j]) ++(*exceed)[j];
    }
  }
  *frames += motion.num_frames();
}

ReconResult run_recon(const NemfModel& model, const runtime::NemfRuntime& runtime, const std::vector<Clip>& clips,
                      const EvalStats& stats, const PriorEvalOptions& options) {
  ReconResult r;
  r.window = model.config().window;
  r.threads = at::get_num_threads();
  std::vector<Window> full, short_clips;
  recon_windows(clips, r.window, options.max_windows, &full, &short_clips);
  SkatingTerms skate_pred, skate_truth;
  double gmp_sum = 0.0;
  for (int pass = 0; pass < 2; ++pass) {
    const std::vector<Window>& windows = pass == 0 ? full : short_clips;
    ReconAccumulator acc;
    double ms = 0.0;
    for (const Window& w : windows) {
      const Motion truth = window_motion(clips, w);
      const auto t0 = Clock::now();
      const Motion pred = decode_motion(runtime, encode_motion(runtime, truth), truth.fps, truth.num_frames());
      ms += ms_since(t0);
      acc.add(truth, pred);
      if (pass == 0) {
        at::NoGradGuard no_grad;
        const WindowTensors t = window_tensors(truth, 0, truth.num_frames(), model.rig(), 0);
        const at::Tensor root = model.root_positions(t.local_rotations, model.predict_global(t.local_rotations));
        gmp_sum += 100.0 * (root - t.root_positions).norm(2, -1).mean().item<double>();
        std::vector<int> frames(truth.num_frames());
        for (int f = 0; f < truth.num_frames(); ++f) frames[f] = f;
        const SkatingTerms sp = foot_skating(forward_kinematics(pred), frames, stats.feet, stats.standing_height);
        const SkatingTerms st = foot_skating(forward_kinematics(truth), frames, stats.feet, stats.standing_height);
        skate_pred.sum_cm += sp.sum_cm, skate_pred.count += sp.count;
        skate_truth.sum_cm += st.sum_cm, skate_truth.count += st.count;
      }
    }
    (pass == 0 ? r.full : r.short_) = acc.summary();
    (pass == 0 ? r.full_ms : r.short_ms) = windows.empty() ? 0.0 : ms / windows.size();
  }
  r.skating_cm = skate_pred.value();
  r.truth_skating_cm = skate_truth.value();
  r.gmp_on_truth_mte_cm = full.empty() ? 0.0 : gmp_sum / full.size();
  return r;
}

FpsResult run_fps(const runtime::NemfRuntime& model, const std::vector<Clip>& clips, const PriorEvalOptions& options) {
  FpsResult r;
  r.threads = at::get_num_threads();
  std::vector<Window> full, short_clips;
  recon_windows(clips, model.config().window, options.max_windows, &full, &short_clips);
  for (double fps : options.fps_list) {
    if (!std::isfinite(fps) || fps <= 0.0) throw InputError("fps list entries must be positive");
    FpsRow row;
    row.fps = fps;
    r.rows.push_back(row);
  }
  const double model_fps = model.config().fps;
  for (const Window& w : full) {
    const Motion truth = window_motion(clips, w);
    const EncodedMotion code = encode_motion(model, truth);
    const double span = (truth.num_frames() - 1) / truth.fps;
    const double truth_acc = mean_joint_acceleration(truth);
    const double truth_local = mean_joint_acceleration(truth, nullptr, true);
    const Motion d30 = decode_motion(model, code, model_fps, static_cast<int>(std::floor(span * model_fps + 1e-6)) + 1);
    const double acc30 = mean_joint_acceleration(d30);
    const double local30 = mean_joint_acceleration(d30, nullptr, true);
    for (FpsRow& row : r.rows) {
      const int frames = static_cast<int>(std::floor(span * row.fps + 1e-6)) + 1;
      const auto t0 = Clock::now();
      const Motion d = decode_motion(model, code, row.fps, frames);
      row.ms += ms_since(t0);
      row.accel += mean_joint_acceleration(d);
      row.accel_30 += acc30;
      row.truth_30 += truth_acc;
      row.local += mean_joint_acceleration(d, nullptr, true);
      row.local_30 += local30;
      row.truth_local_30 += truth_local;
      ++row.windows;
    }
  }
  for (FpsRow& row : r.rows) {
    if (row.windows == 0) continue;
    row.accel /= row.windows;
    row.accel_30 /= row.windows;
    row.truth_30 /= row.windows;
    row.local /= row.windows;
    row.local_30 /= row.windows;
    row.truth_local_30 /= row.windows;
    row.ms /= row.windows;
  }
  return r;
}

SeamResult run_seams(const runtime::NemfRuntime& model, const std::vector<Clip>& clips, const PriorEvalOptions& options) {
  SeamResult r;
  r.threads = at::get_num_threads();
  const int W = model.config().window;
  std::vector<int> long_clips;
  for (size_t c = 0; c < clips.size(); ++c) {
    if (clips[c].motion.num_frames() > W) long_clips.push_back(static_cast<int>(c));
  }
  if (options.max_windows > 0 && static_cast<int>(long_clips.size()) > options.max_windows) {
    std::vector<int> capped;
    for (int i = 0; i < options.max_windows; ++i) capped.push_back(long_clips[i * long_clips.size() / options.max_windows]);
    long_clips = capped;
  }
  long near_jf = 0, else_jf = 0, near_af = 0, else_af = 0;
  double ms = 0.0;
  for (int c : long_clips) {
    const Motion& truth = clips[c].motion;
    const int N = truth.num_frames();
    const auto t0 = Clock::now();
    const EncodedMotion code = encode_motion(model, truth);
    const Motion pred = decode_motion(model, code, truth.fps, N);
    ms += ms_since(t0);
    ++r.clips;
    r.windows += static_cast<int>(code.windows.size());
    // Window boundaries in the clip's frames (the clips run at the model's rate here).
    std::vector<char> near(N, 0);
    const double scale = truth.fps / code.fps;
    for (const WindowCode& w : code.windows) {
      for (double b : {static_cast<double>(w.start), static_cast<double>(w.start + w.length - 1)}) {
        const int f = static_cast<int>(std::lround(b * scale));
        if (f <= 0 || f >= N - 1) continue;
        for (int g = std::max(0, f - options.seam_radius); g <= std::min(N - 1, f + options.seam_radius); ++g) near[g] = 1;
      }
    }
    const GlobalPose tp = forward_kinematics(truth), pp = forward_kinematics(pred);
    for (int f = 0; f < N; ++f) {
      SeamStats& s = near[f] ? r.near : r.elsewhere;
      add_frame_errors(truth, tp, pred, pp, f, &s, near[f] ? &near_jf : &else_jf);
      ++s.frames;
      if (f >= 1 && f <= N - 2) {
        s.accel += accel_sum(pp, f, pred.fps, false);
        s.truth_accel += accel_sum(tp, f, truth.fps, false);
        s.local += accel_sum(pp, f, pred.fps, true);
        s.truth_local += accel_sum(tp, f, truth.fps, true);
        (near[f] ? near_af : else_af) += 1;
      }
    }
  }
  const int J = clips.empty() ? 1 : clips.front().motion.num_joints();
  auto finish = [&](SeamStats& s, long jf, long af) {
    if (jf > 0) {
      s.mre_deg /= static_cast<double>(jf) * (J - 1);
      s.mpe_cm /= static_cast<double>(jf) * (J - 1);
      s.global_cm /= static_cast<double>(jf) * J;
    }
    if (af > 0) {
      s.accel /= static_cast<double>(af) * J;
      s.truth_accel /= static_cast<double>(af) * J;
      s.local /= static_cast<double>(af) * (J - 1);
      s.truth_local /= static_cast<double>(af) * (J - 1);
    }
  };
  finish(r.near, near_jf, near_af);
  finish(r.elsewhere, else_jf, else_af);
  r.ms_per_window = r.windows > 0 ? ms / r.windows : 0.0;
  return r;
}

SampleResult run_sample(const NemfModel& model, const std::vector<Clip>& clips, const std::vector<Clip>& train,
                        const EvalStats& stats, const PriorEvalOptions& options) {
  SampleResult r;
  r.threads = at::get_num_threads();
  const NemfConfig& c = model.config();
  const RigInfo& rig = model.rig();
  const int J = rig.num_joints(), W = c.window;
  const JointLimits limits = compute_joint_limits(train);
  r.percentile = limits.percentile;
  r.joints = rig.skeleton.names;
  for (double a : limits.limit_rad) r.limit_deg.push_back(a * kRadToDeg);

  std::vector<int> all_frames(W);
  for (int f = 0; f < W; ++f) all_frames[f] = f;
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  SkatingTerms skate;
  std::vector<long> exceed(J, 0);
  long frames = 0;
  double ms = 0.0;
  at::NoGradGuard no_grad;
  for (int done = 0; done < options.samples;) {
    const int B = std::min(16, options.samples - done);
    at::Tensor zl = at::empty({B, c.zl}, at::kFloat), zg = at::empty({B, c.zg}, at::kFloat);
    for (int64_t i = 0; i < zl.numel(); ++i) zl.data_ptr<float>()[i] = normal(rng);
    for (int64_t i = 0; i < zg.numel(); ++i) zg.data_ptr<float>()[i] = normal(rng);
    const auto t0 = Clock::now();
    at::Tensor rot = model.decode(at::arange(W, at::kFloat), zl, zg);
    at::Tensor root = model.root_positions(rot, model.predict_global(rot)).to(at::kDouble).contiguous();
    at::Tensor quat = torch_rot::matrix_to_quat(rot).to(at::kDouble).contiguous();
    ms += ms_since(t0);
    const double* q = quat.data_ptr<double>();
    const double* p = root.data_ptr<double>();
    for (int b = 0; b < B; ++b) {
      Motion m = Motion::identity(rig.skeleton, W, c.fps);
      for (int f = 0; f < W; ++f) {
        for (int j = 0; j < J; ++j) {
          const double* e = q + ((static_cast<size_t>(b) * W + f) * J + j) * 4;
          m.rotation(f, j) = Eigen::Quaterniond(e[0], e[1], e[2], e[3]);
        }
        const double* e = p + (static_cast<size_t>(b) * W + f) * 3;
        m.root_positions[f] = Eigen::Vector3d(e[0], e[1], e[2]);
      }
      if (options.on_sample) options.on_sample(m);
      const SkatingTerms s = foot_skating(forward_kinematics(m), all_frames, stats.feet, stats.standing_height);
      skate.sum_cm += s.sum_cm, skate.count += s.count;
      count_limit_exceedances(m, limits, &exceed, &frames);
      r.root_speed += root_speed(m);
      r.local_accel += mean_joint_acceleration(m, nullptr, true);
    }
    done += B;
    r.samples += B;
  }
  r.skating_cm = skate.value();
  if (r.samples > 0) r.root_speed /= r.samples, r.local_accel /= r.samples;
  r.ms_per_window = r.samples > 0 ? ms / r.samples : 0.0;
  for (int j = 0; j < J; ++j) r.sample_fraction.push_back(frames > 0 ? static_cast<double>(exceed[j]) / frames : 0.0);

  std::vector<Window> full, short_clips;
  recon_windows(clips, W, options.max_windows, &full, &short_clips);
  SkatingTerms tskate;
  std::vector<long> texceed(J, 0);
  long tframes = 0;
  for (const Window& w : full) {
    const Motion truth = window_motion(clips, w);
    const SkatingTerms s = foot_skating(forward_kinematics(truth), all_frames, stats.feet, stats.standing_height);
    tskate.sum_cm += s.sum_cm, tskate.count += s.count;
    count_limit_exceedances(truth, limits, &texceed, &tframes);
    r.truth_root_speed += root_speed(truth);
    r.truth_local_accel += mean_joint_acceleration(truth, nullptr, true);
    ++r.truth_windows;
  }
  if (r.truth_windows > 0) r.truth_root_speed /= r.truth_windows, r.truth_local_accel /= r.truth_windows;
  r.truth_skating_cm = tskate.value();
  for (int j = 0; j < J; ++j) r.truth_fraction.push_back(tframes > 0 ? static_cast<double>(texceed[j]) / tframes : 0.0);
  return r;
}

std::string format_recon(const ReconResult& r) {
  std::ostringstream out;
  out << "### Reconstruction (encode then decode, " << r.window << "-frame windows)\n\n";
  out << "torch threads: " << r.threads << "\n\n";
  out << "| windows | count | frames | MRE (deg) | MPE (cm) | MOE (deg) | MTE (cm) | FDE (cm) | ms / window |\n";
  out << "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  auto row = [&](const char* name, const ReconMetrics& m, double ms) {
    out << "| " << name << " | " << m.windows << " | " << m.frames << " | " << fixed(m.mre_deg, 2) << " | "
        << fixed(m.mpe_cm, 2) << " | " << fixed(m.moe_deg, 2) << " | " << fixed(m.mte_cm, 2) << " | "
        << fixed(m.fde_cm, 2) << " | " << fixed(ms, 1) << " |\n";
  };
  row(("full (" + std::to_string(r.window) + " frames)").c_str(), r.full, r.full_ms);
  row(("short clips (< " + std::to_string(r.window) + " frames)").c_str(), r.short_, r.short_ms);
  out << "| NeMF paper (AMASS) | | | 5.99 | 2.87 | 6.16 | 29.7 | 43.0 | |\n\n";
  out << "Foot skating of the reconstruction over the full windows: " << fixed(r.skating_cm, 3)
      << " cm (ground truth " << fixed(r.truth_skating_cm, 3) << " cm). MTE of the global motion predictor fed the "
         "true local rotations instead of the decoded ones: "
      << fixed(r.gmp_on_truth_mte_cm, 2) << " cm.\n";
  return out.str();
}

std::string format_fps(const FpsResult& r) {
  std::ostringstream out;
  out << "### Decoding at other frame rates (mean joint acceleration)\n\n";
  out << "torch threads: " << r.threads << "\n\n";
  auto ratio = [](double a, double b) { return fixed(b > 0 ? a / b : 0.0, 3); };
  out << "| fps | windows | accel (m/s^2) | / 30 fps decode | / ground truth (30 fps) "
         "| root-relative accel (m/s^2) | / 30 fps decode | / ground truth (30 fps) | ms / window |\n";
  out << "|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const FpsRow& row : r.rows) {
    out << "| " << fixed(row.fps, 0) << " | " << row.windows << " | " << fixed(row.accel, 3) << " | "
        << ratio(row.accel, row.accel_30) << " | " << ratio(row.accel, row.truth_30) << " | " << fixed(row.local, 3)
        << " | " << ratio(row.local, row.local_30) << " | " << ratio(row.local, row.truth_local_30) << " | "
        << fixed(row.ms, 1) << " |\n";
  }
  if (!r.rows.empty()) {
    out << "\nGround truth at 30 fps: " << fixed(r.rows.front().truth_30, 3) << " m/s^2 ("
        << fixed(r.rows.front().truth_local_30, 3) << " root-relative); decode at 30 fps: "
        << fixed(r.rows.front().accel_30, 3) << " m/s^2 (" << fixed(r.rows.front().local_30, 3)
        << " root-relative).\n";
  }
  return out.str();
}

std::string format_seams(const SeamResult& r, int radius) {
  std::ostringstream out;
  out << "### Seams between overlapping windows (long clips)\n\n";
  out << "torch threads: " << r.threads << "; " << r.clips << " clips, " << r.windows << " windows; "
      << fixed(r.ms_per_window, 1) << " ms / window (encode + decode)\n\n";
  out << "| frames | count | MRE (deg) | MPE (cm) | global pos (cm) | accel (m/s^2) | accel GT (m/s^2) "
         "| root-relative accel | root-relative accel GT |\n";
  out << "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  auto row = [&](const std::string& name, const SeamStats& s) {
    out << "| " << name << " | " << s.frames << " | " << fixed(s.mre_deg, 2) << " | " << fixed(s.mpe_cm, 2) << " | "
        << fixed(s.global_cm, 2) << " | " << fixed(s.accel, 3) << " | " << fixed(s.truth_accel, 3) << " | "
        << fixed(s.local, 3) << " | " << fixed(s.truth_local, 3) << " |\n";
  };
  row("within " + std::to_string(radius) + " of a window boundary", r.near);
  row("elsewhere", r.elsewhere);
  return out.str();
}

std::string format_sample(const SampleResult& r) {
  std::ostringstream out;
  out << "### Samples from N(0, I)\n\n";
  out << "torch threads: " << r.threads << "; " << r.samples << " samples, " << fixed(r.ms_per_window, 1)
      << " ms / window (decode + global motion predictor); ground truth: " << r.truth_windows
      << " validation windows\n\n";
  out << "| | samples | ground truth |\n|---|---:|---:|\n";
  out << "| foot skating (cm) | " << fixed(r.skating_cm, 3) << " | " << fixed(r.truth_skating_cm, 3) << " |\n";
  out << "| horizontal root speed (m/s) | " << fixed(r.root_speed, 3) << " | " << fixed(r.truth_root_speed, 3) << " |\n";
  out << "| root-relative joint acceleration (m/s^2) | " << fixed(r.local_accel, 3) << " | "
      << fixed(r.truth_local_accel, 3) << " |\n\n";
  double sm = 0.0, tm = 0.0, smax = 0.0;
  int n = 0;
  std::string worst;
  for (size_t j = 1; j < r.joints.size(); ++j) {
    sm += r.sample_fraction[j], tm += r.truth_fraction[j], ++n;
    if (r.sample_fraction[j] > smax) smax = r.sample_fraction[j], worst = r.joints[j];
  }
  if (worst.empty()) worst = "none";
  out << "Joint limits: fraction of frames whose local rotation is farther from the training mean pose than the "
         "training's "
      << fixed(100.0 * r.percentile, 1) << "th percentile for that joint (non-root joints): samples "
      << fixed(n ? 100.0 * sm / n : 0.0, 3) << " % on average (worst " << worst << " " << fixed(100.0 * smax, 2)
      << " %), ground truth " << fixed(n ? 100.0 * tm / n : 0.0, 3) << " %.\n\n";
  out << "| joint | limit (deg) | samples beyond (%) | ground truth beyond (%) |\n";
  out << "|---|---:|---:|---:|\n";
  for (size_t j = 1; j < r.joints.size(); ++j) {
    out << "| " << r.joints[j] << " | " << fixed(r.limit_deg[j], 1) << " | " << fixed(100.0 * r.sample_fraction[j], 2)
        << " | " << fixed(100.0 * r.truth_fraction[j], 2) << " |\n";
  }
  return out.str();
}

}  // namespace mf::bench
