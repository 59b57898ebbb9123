#include "tasks/initializers.h"

#include <ATen/ATen.h>

#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "tasks/baselines.h"
#include "tasks/transformer_methods.h"

namespace mf {

namespace {

// Value at frame f of a series known at sorted `frames`: interpolated between
// the surrounding known frames, held before the first and after the last.
template <typename Lerp, typename Get>
auto interpolate_at(int f, const std::vector<int>& frames, Get get, Lerp lerp) {
  auto it = std::lower_bound(frames.begin(), frames.end(), f);
  if (it == frames.end()) return get(frames.back());
  if (*it == f || it == frames.begin()) return get(*it);
  const int b = *it, a = *(it - 1);
  return lerp(get(a), get(b), static_cast<double>(f - a) / (b - a));
}

}  // namespace

Motion fill_by_interpolation(const Motion& window, const MotionConstraints& constraints) {
  bool full = true;
  std::vector<int> frames;
  for (size_t k = 0; k < constraints.keys.size(); ++k) {
    full = full && constraints.keys[k].joints.empty() && constraints.keys[k].root_position;
    frames.push_back(constraints.keys[k].frame);
  }
  if (frames.empty()) throw InputError("interpolation needs at least one key");
  if (full) return interpolate_motion(window, frames);

  const int T = window.num_frames(), J = window.num_joints();
  Motion out = Motion::identity(window.skeleton, T, window.fps);
  for (int j = 0; j < J; ++j) {
    std::vector<int> known;
    for (size_t k = 0; k < constraints.keys.size(); ++k) {
      if (constraints.key_has_joint(k, j)) known.push_back(constraints.keys[k].frame);
    }
    if (known.empty()) continue;
    for (int f = 0; f < T; ++f) {
      out.rotation(f, j) = interpolate_at(
          f, known, [&](int g) { return window.rotation(g, j).normalized(); },
          [](const Eigen::Quaterniond& a, const Eigen::Quaterniond& b, double t) { return slerp(a, b, t); });
    }
  }
  std::vector<int> rooted;
  for (const PoseKey& k : constraints.keys) {
    if (k.root_position) rooted.push_back(k.frame);
  }
  if (!rooted.empty()) {
    for (int f = 0; f < T; ++f) {
      out.root_positions[f] = interpolate_at(
          f, rooted, [&](int g) { return window.root_positions[g]; },
          [](const Eigen::Vector3d& a, const Eigen::Vector3d& b, double t) -> Eigen::Vector3d {
            return a + (b - a) * t;
          });
    }
  }
  return out;
}

InitialGuess encode_window(const NemfModel& model, const Motion& window, int anchor) {
  at::NoGradGuard no_grad;
  const int T = window.num_frames();
  if (T < 2 || T > model.config().window)
    throw InputError("encode_window: the window must have 2 to " + std::to_string(model.config().window) + " frames");
  WindowTensors w = window_tensors(window, 0, T, model.rig(), anchor);
  NemfLatent z = model.encode(w.local_rotations, at::ones({1, T}, at::kFloat));
  return {z.mu_l.detach().clone(), z.mu_g.detach().clone()};
}

InitialGuess InterpolationEncoderInitializer::initialize(const InitRequest& r) const {
  if (!r.model || !r.window || !r.constraints) throw std::invalid_argument("InitRequest is incomplete");
  return encode_window(*r.model, fill_by_interpolation(*r.window, *r.constraints), r.anchor);
}

InitialGuess ZeroInitializer::initialize(const InitRequest& r) const {
  if (!r.model) throw std::invalid_argument("InitRequest is incomplete");
  return {at::zeros({1, r.model->config().zl}, at::kFloat), at::zeros({1, r.model->config().zg}, at::kFloat)};
}

TransformerEncoderInitializer::TransformerEncoderInitializer(std::string name, std::string kind, int stage,
                                                             std::shared_ptr<const InbetweenModel> bound)
    : name_(std::move(name)), kind_(std::move(kind)), stage_(stage), bound_(std::move(bound)) {}

InitialGuess TransformerEncoderInitializer::initialize(const InitRequest& r) const {
  if (!r.model || !r.window || !r.constraints) throw std::invalid_argument("InitRequest is incomplete");
  const InbetweenModel* transformer = bound_ ? bound_.get() : r.context ? r.context->inbetweener(kind_) : nullptr;
  if (!transformer) throw InputError(missing_inbetweener_message("initialiser '" + name_ + "'", kind_));
  const Motion filled = inbetweener_fill(*transformer, stage_, *r.window, *r.constraints, LongGapPolicy::Interpolate);
  return encode_window(*r.model, filled, r.anchor);
}

std::vector<std::string> initializer_names() {
  return {"interp-encoder", "zero", "context-encoder", "detail-encoder", "citl-encoder"};
}

namespace {

std::shared_ptr<const LatentInitializer> make_named(const std::string& name, const TaskContext* context) {
  if (name == "interp-encoder") return std::make_shared<InterpolationEncoderInitializer>();
  if (name == "zero") return std::make_shared<ZeroInitializer>();
  struct Transformer {
    const char* name;
    const char* kind;
    int stage;
  };
  for (const Transformer& t : {Transformer{"context-encoder", "twostage", 0}, Transformer{"detail-encoder", "twostage", 1},
                               Transformer{"citl-encoder", "citl", -1}}) {
    if (name != t.name) continue;
    std::shared_ptr<const InbetweenModel> bound;
    if (context) {
      bound = t.kind == std::string("citl") ? context->citl : context->twostage;
      if (!bound) throw InputError(missing_inbetweener_message("initialiser '" + name + "'", t.kind));
    }
    return std::make_shared<TransformerEncoderInitializer>(t.name, t.kind, t.stage, std::move(bound));
  }
  std::string list;
  for (const std::string& n : initializer_names()) list += (list.empty() ? "" : ", ") + n;
  throw InputError("unknown initialiser '" + name + "' (available: " + list + ")");
}

}  // namespace

std::shared_ptr<const LatentInitializer> make_initializer(const std::string& name) { return make_named(name, nullptr); }

std::shared_ptr<const LatentInitializer> make_initializer(const std::string& name, const TaskContext& context) {
  return make_named(name, &context);
}

}  // namespace mf
