#include "tasks/latent/prior_codec.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "prior/runtime/nemf_runtime.h"
#include "prior/runtime/root_path.h"
#include "prior/runtime/rotations.h"
#include "tasks/constraints/interpolation_fill.h"

namespace mf {
namespace {

constexpr double kPi = 3.14159265358979323846;

// CodecPrior on the Eigen runtime, with the buffers of its evaluations: one
// per call of the codec.
class RuntimeCodecPrior final : public CodecPrior {
 public:
  explicit RuntimeCodecPrior(const runtime::NemfRuntime& model) : model_(model), kinematics_(model.rig().skeleton) {}
  const NemfConfig& config() const override { return model_.config(); }
  const RigInfo& rig() const override { return model_.rig(); }

  void encode(const Rows& local_rotations, Eigen::VectorXf* z_l, Eigen::VectorXf* z_g) const override {
    runtime::LatentGaussians z = model_.encode_rotations(local_rotations);
    *z_l = std::move(z.mu_l);
    *z_g = std::move(z.mu_g);
  }

  void decode(const WindowCode& window, const Eigen::VectorXd& positions, Rows* rotations) const override {
    model_.decode(positions, window.z_l, window.z_g, &decoder_ws_, &sixd_);
    runtime::sixd_to_matrix(sixd_, rotations);
  }

  void root_path(const WindowCode& window, Rows* path) const override {
    decode(window, Eigen::VectorXd::LinSpaced(window.length, 0.0, window.length - 1.0), &rotations_);
    zero_root_.setZero(window.length, 3);
    kinematics_.forward(rotations_, zero_root_, &positions_, &globals_);
    runtime::gmp_inputs(rotations_, positions_, rig().root_forward.cast<float>(), &headings_, &gmp_in_);
    model_.predict_global(gmp_in_, GmpUse::Default, &gmp_ws_, &gmp_out_);
    runtime::integrate_root_path(headings_, gmp_out_, config().fps, path);
  }

 private:
  const runtime::NemfRuntime& model_;
  runtime::Kinematics kinematics_;
  mutable runtime::DecoderWorkspace decoder_ws_;
  mutable runtime::GmpWorkspace gmp_ws_;
  mutable runtime::MatrixRXf sixd_, rotations_, zero_root_, positions_, globals_, headings_, gmp_in_, gmp_out_;
};

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

void check_code(const CodecPrior& model, const EncodedMotion& code) {
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
    if (w.z_l.size() != c.zl || w.z_g.size() != c.zg) {
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

EncodedMotion encode_motion(const CodecPrior& prior, const Motion& motion, const CodecOptions& options) {
  motion.validate();
  if (motion.num_frames() < 2) throw InputError("the prior needs a motion of at least 2 frames");
  const RigInfo& rig = prior.rig();
  check_model_skeleton(rig, motion.skeleton, "motion");
  const NemfConfig& c = prior.config();
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
  const int len = std::min(N, c.window);
  for (int start : window_starts(N, c.window, hop)) {
    WindowCode w;
    w.start = start;
    w.length = len;
    w.transform = canonical_transform(*src, start, rig);
    prior.encode(window_matrices(*src, start, len, rig, 0).local_rotations, &w.z_l, &w.z_g);
    code.windows.push_back(std::move(w));
  }
  return code;
}

EncodedMotion encode_motion(const runtime::NemfRuntime& model, const Motion& motion, const CodecOptions& options) {
  return encode_motion(RuntimeCodecPrior(model), motion, options);
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

// Adds window k's weighted quaternions, decoded at its samples' local
// positions (root orientation in the world frame), each flipped into the
// hemisphere of the sum so far, to `qsum` [T * J].
void accumulate_rotations(const CodecPrior& prior, const std::vector<WindowCode>& win, const WindowSamples& samples,
                          const std::vector<double>& pos, int k, int J, std::vector<Eigen::Vector4d>* qsum) {
  const std::vector<int>& members = samples.members[k];
  Eigen::VectorXd local(members.size());
  for (size_t m = 0; m < members.size(); ++m) local[m] = pos[members[m]] - win[k].start;
  CodecPrior::Rows rotations;
  prior.decode(win[k], local, &rotations);
  const Eigen::Quaterniond turn = yaw_quat(win[k].transform.yaw);
  for (size_t m = 0; m < members.size(); ++m) {
    const int i = members[m];
    const double w = samples.weights[k][m] / samples.weight_sum[i];
    for (int j = 0; j < J; ++j) {
      Eigen::Vector4d v = runtime::matrix_to_quat(&rotations(m, j * 9)).cast<double>();  // (w, x, y, z)
      if (j == 0) {
        Eigen::Quaterniond r = turn * Eigen::Quaterniond(v[0], v[1], v[2], v[3]);
        v = Eigen::Vector4d(r.w(), r.x(), r.y(), r.z());
      }
      Eigen::Vector4d& acc = (*qsum)[static_cast<size_t>(i) * J + j];
      acc += (acc.dot(v) < 0.0 ? -w : w) * v;
    }
  }
}

// Adds window k's weighted root path (the global motion predictor's, placed
// by its GroundTransform; Catmull-Rom between model frames) to `psum`.
void accumulate_prior_root(const CodecPrior& prior, const std::vector<WindowCode>& win, const WindowSamples& samples,
                           const std::vector<double>& pos, int k, std::vector<Eigen::Vector3d>* psum) {
  CodecPrior::Rows path;
  prior.root_path(win[k], &path);
  const int len = win[k].length;
  const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> root = path.cast<double>();
  const Eigen::Matrix3d turn = yaw_quat(win[k].transform.yaw).toRotationMatrix();
  const Eigen::Vector3d shift(win[k].transform.x, 0.0, win[k].transform.z);
  for (size_t m = 0; m < samples.members[k].size(); ++m) {
    const int i = samples.members[k][m];
    const double w = samples.weights[k][m] / samples.weight_sum[i];
    const double s = std::clamp(pos[i] - win[k].start, 0.0, static_cast<double>(len - 1));
    (*psum)[i] += w * (turn * catmull_rom(root.data(), len, s) + shift);
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

Motion decode_times(const CodecPrior& prior, const EncodedMotion& code, const std::vector<double>& times, double fps,
                    const DecodeOptions& options) {
  check_fps(fps, "decode fps");
  check_code(prior, code);
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
  for (int k = 0; k < K; ++k) {
    if (samples.members[k].empty()) continue;
    accumulate_rotations(prior, win, samples, pos, k, J, &qsum);
    if (options.root == RootSource::kPrior) accumulate_prior_root(prior, win, samples, pos, k, &psum);
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

Motion decode_times(const runtime::NemfRuntime& model, const EncodedMotion& code, const std::vector<double>& times,
                    double fps, const DecodeOptions& options) {
  return decode_times(RuntimeCodecPrior(model), code, times, fps, options);
}

Motion decode_motion(const CodecPrior& prior, const EncodedMotion& code, double fps, int frames,
                     const DecodeOptions& options) {
  check_fps(fps, "decode fps");
  if (frames < 0) throw InputError("decode frame count must not be negative");
  std::vector<double> times(frames);
  for (int i = 0; i < frames; ++i) times[i] = i / fps;
  return decode_times(prior, code, times, fps, options);
}

Motion decode_motion(const runtime::NemfRuntime& model, const EncodedMotion& code, double fps, int frames,
                     const DecodeOptions& options) {
  return decode_motion(RuntimeCodecPrior(model), code, fps, frames, options);
}

namespace {

// Encodes `input`, decodes at times i / fps and, with the residual, corrects
// the decode so that it passes through the frames of `input`.
Motion resample_core(const CodecPrior& prior, const Motion& input, double fps, int frames,
                     const PriorResampleOptions& options) {
  EncodedMotion code = encode_motion(prior, input, options.codec);
  const int N = input.num_frames();
  const int J = input.num_joints();

  // One decode for the output times and (for the residual) the input frames.
  std::vector<double> times(frames);
  for (int i = 0; i < frames; ++i) times[i] = i / fps;
  if (options.residual) {
    for (int k = 0; k < N; ++k) times.push_back(k / input.fps);
  }
  Motion all = decode_times(prior, code, times, fps, DecodeOptions{options.root});
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

Motion resample_with_prior(const CodecPrior& prior, const Motion& motion, double fps, int frames,
                           const PriorResampleOptions& options) {
  check_fps(fps, "output fps");
  if (frames < 0) throw InputError("output frame count must not be negative");
  motion.validate();
  return resample_core(prior, motion, fps, frames, options);
}

Motion resample_with_prior(const Motion& motion, double fps, int frames, const TaskContext& ctx,
                           const PriorResampleOptions& options) {
  if (!ctx.model) throw ModelMissingError("resampling with the prior needs a model, and none is loaded");
  return resample_with_prior(RuntimeCodecPrior(*ctx.model), motion, fps, frames, options);
}

}  // namespace mf
