#include "tasks/latent/prior_codec.h"

#include <ATen/ATen.h>
#include <torch/types.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "prior/motion/rotations_torch.h"
#include "tasks/constraints/interpolation_fill.h"

namespace mf {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Windows per encoder / decoder call: bounds memory on long clips.
constexpr int kWindowBatch = 16;

void check_fps(double fps, const char* what) {
  if (!std::isfinite(fps) || fps <= 0.0) throw InputError(std::string(what) + " must be finite and positive");
}

// Uniform Catmull-Rom spline through points p[0 .. n-1] ([n, 3] row-major) at
// position s in [0, n - 1]; end points are repeated. C1, exact at integers.
Eigen::Vector3d catmull_rom(const double* p, int n, double s) {
  const int a = std::min(static_cast<int>(std::floor(s)), n - 1);
  const double u = s - a;
  auto at = [&](int i) {
    i = std::clamp(i, 0, n - 1);
    return Eigen::Vector3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
  };
  if (u == 0.0) return at(a);
  const Eigen::Vector3d p0 = at(a - 1), p1 = at(a), p2 = at(a + 1), p3 = at(a + 2);
  const double u2 = u * u, u3 = u2 * u;
  return 0.5 * ((2.0 * p1) + (p2 - p0) * u + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * u2 +
                (3.0 * p1 - p0 - 3.0 * p2 + p3) * u3);
}

Eigen::Quaterniond yaw_quat(double yaw) { return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY())); }

// Unnormalised weight of window k at position s (see the header).
double raw_weight(const std::vector<WindowCode>& w, size_t k, double s) {
  const double a = w[k].start, b = w[k].start + w[k].length - 1;
  if (s < a || s > b) return 0.0;
  double weight = 1.0;
  if (k > 0) {
    const double prev_end = w[k - 1].start + w[k - 1].length - 1;
    if (prev_end > a && s < prev_end) weight *= 0.5 - 0.5 * std::cos(kPi * (s - a) / (prev_end - a));
  }
  if (k + 1 < w.size()) {
    const double next_start = w[k + 1].start;
    if (next_start < b && s > next_start) weight *= 0.5 + 0.5 * std::cos(kPi * (s - next_start) / (b - next_start));
  }
  return weight;
}

void check_code(const NemfModel& model, const EncodedMotion& code) {
  const NemfConfig& c = model.config();
  if (code.windows.empty() || code.frames < 1) throw InputError("encoded motion has no windows");
  if (code.skeleton.num_joints() != model.rig().num_joints()) {
    throw InputError("encoded motion's skeleton does not match the model's rig");
  }
  check_fps(code.fps, "encoded motion's fps");
  int prev = -1;
  for (const WindowCode& w : code.windows) {
    if (w.start <= prev || w.length < 1 || w.length > c.window || w.start + w.length > code.frames) {
      throw InputError("encoded motion's windows are not sorted, overlap the sequence's end or exceed the model window");
    }
    prev = w.start;
    if (!w.z_l.defined() || !w.z_g.defined() || w.z_l.numel() != c.zl || w.z_g.numel() != c.zg) {
      throw InputError("encoded motion's latents do not match the model (z_l " + std::to_string(c.zl) + ", z_g " +
                       std::to_string(c.zg) + ")");
    }
  }
}

}  // namespace

std::vector<double> blend_weights(const std::vector<WindowCode>& windows, double s) {
  std::vector<double> w(windows.size(), 0.0);
  if (windows.empty()) return w;
  double lo = windows.front().start, hi = lo;
  for (const WindowCode& c : windows) {
    lo = std::min<double>(lo, c.start);
    hi = std::max<double>(hi, c.start + c.length - 1);
  }
  s = std::clamp(s, lo, hi);
  double sum = 0.0;
  for (size_t k = 0; k < windows.size(); ++k) sum += (w[k] = raw_weight(windows, k, s));
  if (sum > 0.0) {
    for (double& x : w) x /= sum;
  } else {
    // Only for degenerate layouts (a gap between windows): the nearest window.
    size_t best = 0;
    double best_d = 1e300;
    for (size_t k = 0; k < windows.size(); ++k) {
      const double d = std::max({0.0, windows[k].start - s, s - (windows[k].start + windows[k].length - 1)});
      if (d < best_d) best_d = d, best = k;
    }
    w[best] = 1.0;
  }
  return w;
}

EncodedMotion encode_motion(const NemfModel& model, const Motion& motion, const CodecOptions& options) {
  motion.validate();
  if (motion.num_frames() < 2) throw InputError("the prior needs a motion of at least 2 frames");
  check_model_skeleton(model.rig(), motion.skeleton, "motion");
  const NemfConfig& c = model.config();
  const int hop = options.hop == 0 ? c.window / 2 : options.hop;
  if (hop < 1 || hop >= c.window) {
    throw InputError("codec hop must lie in [1, " + std::to_string(c.window - 1) + "]");
  }

  // The sequence at the model's rate.
  Motion seq;
  const Motion* src = &motion;
  if (!same_frame_rate(motion.fps, c.fps)) {
    const double span = (motion.num_frames() - 1) * c.fps / motion.fps;
    // Checked before the cast: a tiny input fps makes the span overflow an int.
    if (!(span < 10000000.0)) throw InputError("motion too long to encode");
    const int n = static_cast<int>(std::ceil(span - 1e-5)) + 1;
    seq = resample_interpolate(motion, c.fps, std::max(2, n));
    src = &seq;
  }
  const int N = src->num_frames();

  EncodedMotion code;
  code.skeleton = motion.skeleton;
  code.fps = c.fps;
  code.frames = N;
  code.source_fps = motion.fps;
  code.source_root_positions = motion.root_positions;
  const std::vector<int> starts = window_starts(N, c.window, hop);
  const int len = std::min(N, c.window);

  at::NoGradGuard no_grad;
  const RigInfo& rig = model.rig();
  for (size_t b0 = 0; b0 < starts.size(); b0 += kWindowBatch) {
    const size_t b1 = std::min(starts.size(), b0 + kWindowBatch);
    std::vector<at::Tensor> rots;
    for (size_t k = b0; k < b1; ++k) rots.push_back(window_tensors(*src, starts[k], len, rig, 0).local_rotations);
    at::Tensor rot = at::cat(rots, 0);
    NemfLatent z = model.encode(rot, at::ones({rot.size(0), len}, at::kFloat));
    for (size_t k = b0; k < b1; ++k) {
      WindowCode w;
      w.start = starts[k];
      w.length = len;
      w.transform = canonical_transform(*src, starts[k], rig);
      w.z_l = z.mu_l[static_cast<int64_t>(k - b0)].clone();
      w.z_g = z.mu_g[static_cast<int64_t>(k - b0)].clone();
      code.windows.push_back(std::move(w));
    }
  }
  return code;
}

namespace {

// Which samples each window covers and with what weight: per window k the
// samples i it weighs (members[k]) and their raw weights (weights[k]); per
// sample the sum of its raw weights.
struct WindowSamples {
  std::vector<std::vector<int>> members;
  std::vector<std::vector<double>> weights;
  std::vector<double> weight_sum;
};

WindowSamples assign_samples(const std::vector<WindowCode>& win, const std::vector<double>& pos) {
  const int T = static_cast<int>(pos.size()), K = static_cast<int>(win.size());
  // The samples sorted by position, so that each window finds its own by bisection.
  std::vector<int> order(T);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return pos[a] < pos[b]; });
  WindowSamples out{std::vector<std::vector<int>>(K), std::vector<std::vector<double>>(K), std::vector<double>(T, 0.0)};
  for (int k = 0; k < K; ++k) {
    const double a = win[k].start, b = win[k].start + win[k].length - 1;
    auto lo = std::lower_bound(order.begin(), order.end(), a, [&](int i, double v) { return pos[i] < v; });
    auto hi = std::upper_bound(order.begin(), order.end(), b, [&](double v, int i) { return v < pos[i]; });
    for (auto it = lo; it != hi; ++it) {
      const double w = raw_weight(win, k, pos[*it]);
      if (w <= 0.0) continue;
      out.members[k].push_back(*it);
      out.weights[k].push_back(w);
      out.weight_sum[*it] += w;
    }
  }
  // Degenerate layouts only (gaps): samples no window weighs take the nearest window.
  for (int i = 0; i < T; ++i) {
    if (out.weight_sum[i] > 0.0) continue;
    std::vector<double> w = blend_weights(win, pos[i]);
    const int k = static_cast<int>(std::max_element(w.begin(), w.end()) - w.begin());
    out.members[k].push_back(i);
    out.weights[k].push_back(1.0);
    out.weight_sum[i] = 1.0;
  }
  return out;
}

// Windows [k0, k1) decoded at their samples' local positions (rows padded to
// the most samples, `smax`): quaternions [B, smax, J, 4], double.
at::Tensor decode_window_batch(const NemfModel& model, const std::vector<WindowCode>& win, const WindowSamples& samples,
                               const std::vector<double>& pos, int k0, int k1, size_t smax, at::Tensor* z_l,
                               at::Tensor* z_g) {
  at::Tensor frames = at::zeros({k1 - k0, static_cast<int64_t>(smax)}, at::kFloat);
  std::vector<at::Tensor> zl, zg;
  float* f = frames.data_ptr<float>();
  for (int k = k0; k < k1; ++k) {
    for (size_t m = 0; m < samples.members[k].size(); ++m) {
      f[(k - k0) * smax + m] = static_cast<float>(pos[samples.members[k][m]] - win[k].start);
    }
    zl.push_back(win[k].z_l.reshape({1, -1}).to(at::kFloat));
    zg.push_back(win[k].z_g.reshape({1, -1}).to(at::kFloat));
  }
  *z_l = at::cat(zl, 0);
  *z_g = at::cat(zg, 0);
  return torch_rot::matrix_to_quat(model.decode(frames, *z_l, *z_g)).to(at::kDouble).contiguous();
}

// Adds the windows' weighted quaternions (root orientation in the world
// frame), each flipped into the hemisphere of the sum so far, to `qsum` [T * J].
void accumulate_rotations(const at::Tensor& quat, const std::vector<WindowCode>& win, const WindowSamples& samples,
                          int k0, int k1, size_t smax, int J, std::vector<Eigen::Vector4d>* qsum) {
  const double* q = quat.data_ptr<double>();  // [B, smax, J, 4]
  for (int k = k0; k < k1; ++k) {
    const Eigen::Quaterniond turn = yaw_quat(win[k].transform.yaw);
    for (size_t m = 0; m < samples.members[k].size(); ++m) {
      const int i = samples.members[k][m];
      const double w = samples.weights[k][m] / samples.weight_sum[i];
      const double* qs = q + ((static_cast<size_t>(k - k0) * smax + m) * J) * 4;
      for (int j = 0; j < J; ++j) {
        Eigen::Vector4d v(qs[4 * j], qs[4 * j + 1], qs[4 * j + 2], qs[4 * j + 3]);
        if (j == 0) {
          Eigen::Quaterniond r = turn * Eigen::Quaterniond(v[0], v[1], v[2], v[3]);
          v = Eigen::Vector4d(r.w(), r.x(), r.y(), r.z());
        }
        Eigen::Vector4d& acc = (*qsum)[static_cast<size_t>(i) * J + j];
        acc += (acc.dot(v) < 0.0 ? -w : w) * v;
      }
    }
  }
}

// Adds the windows' weighted root paths (the global motion predictor's, per
// window, placed by its GroundTransform; Catmull-Rom between model frames) to `psum`.
void accumulate_prior_roots(const NemfModel& model, const std::vector<WindowCode>& win, const WindowSamples& samples,
                            const std::vector<double>& pos, int k0, int k1, const at::Tensor& z_l,
                            const at::Tensor& z_g, std::vector<Eigen::Vector3d>* psum) {
  const int len = win[k0].length;
  bool same_length = true;
  for (int k = k0; k < k1; ++k) same_length = same_length && win[k].length == len;
  // One batch when the windows have one length (always, for encode_motion's codes).
  std::vector<std::pair<int, int>> groups;
  if (same_length) {
    groups.emplace_back(k0, k1);
  } else {
    for (int k = k0; k < k1; ++k) groups.emplace_back(k, k + 1);
  }
  for (auto [g0, g1] : groups) {
    const int glen = win[g0].length;
    at::Tensor dense =
        model.decode(at::arange(glen, at::kFloat), z_l.narrow(0, g0 - k0, g1 - g0), z_g.narrow(0, g0 - k0, g1 - g0));
    at::Tensor root = model.root_positions(dense, model.predict_global(dense)).to(at::kDouble).contiguous();  // [G, len, 3]
    const double* r = root.data_ptr<double>();
    for (int k = g0; k < g1; ++k) {
      const Eigen::Matrix3d turn = yaw_quat(win[k].transform.yaw).toRotationMatrix();
      const Eigen::Vector3d shift(win[k].transform.x, 0.0, win[k].transform.z);
      const double* rk = r + static_cast<size_t>(k - g0) * glen * 3;
      for (size_t m = 0; m < samples.members[k].size(); ++m) {
        const int i = samples.members[k][m];
        const double w = samples.weights[k][m] / samples.weight_sum[i];
        const double s = std::clamp(pos[i] - win[k].start, 0.0, static_cast<double>(glen - 1));
        (*psum)[i] += w * (turn * catmull_rom(rk, glen, s) + shift);
      }
    }
  }
}

// RootSource::kInput: the input's root path, linear between its frames, at `times`.
void input_root_path(const EncodedMotion& code, const std::vector<double>& times, Motion* out) {
  const std::vector<Eigen::Vector3d>& src = code.source_root_positions;
  const int n = static_cast<int>(src.size());
  for (size_t i = 0; i < times.size(); ++i) {
    const double s = std::clamp(snap_frame_position(times[i] * code.source_fps), 0.0, static_cast<double>(n - 1));
    const int a = static_cast<int>(std::floor(s));
    const int b = std::min(a + 1, n - 1);
    const double u = s - a;
    out->root_positions[i] = u == 0.0 ? src[a] : Eigen::Vector3d((1.0 - u) * src[a] + u * src[b]);
  }
}

}  // namespace

Motion decode_times(const NemfModel& model, const EncodedMotion& code, const std::vector<double>& times, double fps,
                    const DecodeOptions& options) {
  check_fps(fps, "decode fps");
  check_code(model, code);
  for (double t : times) {
    if (!std::isfinite(t)) throw InputError("decode times must be finite");
  }
  if (options.root == RootSource::kInput && code.source_root_positions.empty()) {
    throw InputError("decoding with the input's root path needs EncodedMotion::source_root_positions");
  }
  const int T = static_cast<int>(times.size());
  const int J = code.skeleton.num_joints();
  const std::vector<WindowCode>& win = code.windows;
  const int K = static_cast<int>(win.size());
  Motion out = Motion::identity(code.skeleton, T, fps);
  if (T == 0) return out;

  // Model-frame positions, clamped to the sequence; the windows' samples.
  std::vector<double> pos(T);
  for (int i = 0; i < T; ++i) pos[i] = std::clamp(times[i] * code.fps, 0.0, static_cast<double>(code.frames - 1));
  const WindowSamples samples = assign_samples(win, pos);

  std::vector<Eigen::Vector4d> qsum(static_cast<size_t>(T) * J, Eigen::Vector4d::Zero());
  std::vector<Eigen::Vector3d> psum(T, Eigen::Vector3d::Zero());
  at::NoGradGuard no_grad;
  for (int k0 = 0; k0 < K; k0 += kWindowBatch) {
    const int k1 = std::min(K, k0 + kWindowBatch);
    size_t smax = 1;
    for (int k = k0; k < k1; ++k) smax = std::max(smax, samples.members[k].size());
    at::Tensor z_l, z_g;
    const at::Tensor quat = decode_window_batch(model, win, samples, pos, k0, k1, smax, &z_l, &z_g);
    accumulate_rotations(quat, win, samples, k0, k1, smax, J, &qsum);
    if (options.root == RootSource::kPrior) accumulate_prior_roots(model, win, samples, pos, k0, k1, z_l, z_g, &psum);
  }

  for (int i = 0; i < T; ++i) {
    for (int j = 0; j < J; ++j) {
      const Eigen::Vector4d& v = qsum[static_cast<size_t>(i) * J + j];
      out.rotation(i, j) = Eigen::Quaterniond(v[0], v[1], v[2], v[3]).normalized();
    }
  }
  if (options.root == RootSource::kPrior) {
    out.root_positions = psum;
  } else {
    input_root_path(code, times, &out);
  }
  return out;
}

Motion decode_motion(const NemfModel& model, const EncodedMotion& code, double fps, int frames,
                     const DecodeOptions& options) {
  check_fps(fps, "decode fps");
  if (frames < 0) throw InputError("decode frame count must not be negative");
  std::vector<double> times(frames);
  for (int i = 0; i < frames; ++i) times[i] = i / fps;
  return decode_times(model, code, times, fps, options);
}

namespace {

// Encodes `input`, decodes at times i / fps and, with the residual, corrects
// the decode so that it passes through the frames of `input`.
Motion resample_core(const NemfModel& model, const Motion& input, double fps, int frames,
                     const PriorResampleOptions& options) {
  EncodedMotion code = encode_motion(model, input, options.codec);
  const int N = input.num_frames();
  const int J = input.num_joints();

  // One decode for the output times and (for the residual) the input frames.
  std::vector<double> times(frames);
  for (int i = 0; i < frames; ++i) times[i] = i / fps;
  if (options.residual) {
    for (int k = 0; k < N; ++k) times.push_back(k / input.fps);
  }
  Motion all = decode_times(model, code, times, fps, DecodeOptions{options.root});
  Motion out = all.slice(0, frames);
  if (!options.residual) return out;

  std::vector<Eigen::Quaterniond> rot_res(static_cast<size_t>(N) * J);
  std::vector<Eigen::Vector3d> pos_res(N);
  for (int k = 0; k < N; ++k) {
    for (int j = 0; j < J; ++j) {
      rot_res[static_cast<size_t>(k) * J + j] =
          (input.rotation(k, j).normalized() * all.rotation(frames + k, j).conjugate()).normalized();
    }
    pos_res[k] = input.root_positions[k] - all.root_positions[frames + k];
  }
  for (int i = 0; i < frames; ++i) {
    const double s = std::min(snap_frame_position(i * input.fps / fps), static_cast<double>(N - 1));
    const int a = static_cast<int>(std::floor(s));
    const double u = s - a;
    if (u == 0.0) {
      for (int j = 0; j < J; ++j) out.rotation(i, j) = input.rotation(a, j);
      out.root_positions[i] = input.root_positions[a];
      continue;
    }
    const int b = std::min(a + 1, N - 1);
    for (int j = 0; j < J; ++j) {
      const Eigen::Quaterniond r =
          slerp(rot_res[static_cast<size_t>(a) * J + j], rot_res[static_cast<size_t>(b) * J + j], u);
      out.rotation(i, j) = (r * out.rotation(i, j)).normalized();
    }
    out.root_positions[i] += (1.0 - u) * pos_res[a] + u * pos_res[b];
  }
  return out;
}

}  // namespace

Motion resample_with_prior(const Motion& motion, double fps, int frames, const TaskContext& ctx,
                           const PriorResampleOptions& options) {
  if (!ctx.model) throw ModelMissingError("resampling with the prior needs a model, and none is loaded");
  check_fps(fps, "output fps");
  if (frames < 0) throw InputError("output frame count must not be negative");
  motion.validate();
  return resample_core(*ctx.model, motion, fps, frames, options);
}

}  // namespace mf
