#include "tasks/latent/initializers.h"

#include "prior/inbetween/inbetweener_kinds.h"
#include "prior/motion/errors.h"
#include "prior/model/canonical_window.h"
#include "prior/motion/rotations.h"
#include "prior/runtime/nemf_runtime.h"
#include "tasks/constraints/interpolation_fill.h"
#include "tasks/transformer/inbetweener_files.h"
#include "tasks/transformer/inbetweener_fill.h"

namespace mf {

InitialGuess encode_window(const runtime::NemfRuntime& model, const Motion& window, int anchor) {
  const int T = window.num_frames();
  if (T < 2 || T > model.config().window)
    throw InputError("encode_window: the window must have 2 to " + std::to_string(model.config().window) + " frames");
  const runtime::LatentGaussians z =
      model.encode_rotations(window_matrices(window, 0, T, model.rig(), anchor).local_rotations);
  return {z.mu_l, z.mu_g};
}

InitialGuess encode_window(const InitRequest& r, const Motion& window) {
  if (!r.model) throw std::invalid_argument("InitRequest is incomplete");
  return encode_window(*r.model, window, r.anchor);
}

std::optional<Motion> LatentInitializer::fill_input(const Motion&, const MotionConstraints&, const TaskContext&) const {
  return std::nullopt;
}

InitialGuess InterpolationEncoderInitializer::initialize(const InitRequest& r) const {
  if (!r.window || !r.constraints) throw std::invalid_argument("InitRequest is incomplete");
  return encode_window(r, fill_by_interpolation(*r.window, *r.constraints));
}

std::optional<Motion> InterpolationEncoderInitializer::fill_input(const Motion& input, const MotionConstraints& c,
                                                                  const TaskContext&) const {
  return fill_by_interpolation(input, c);
}

InitialGuess ZeroInitializer::initialize(const InitRequest& r) const {
  if (!r.model) throw std::invalid_argument("InitRequest is incomplete");
  const NemfConfig& config = r.model->config();
  return {Eigen::VectorXf::Zero(config.zl), Eigen::VectorXf::Zero(config.zg)};
}

TransformerEncoderInitializer::TransformerEncoderInitializer(
    std::string name, std::string kind, int stage, std::shared_ptr<const runtime::InbetweenerRuntime> bound)
    : name_(std::move(name)), kind_(std::move(kind)), stage_(stage), bound_(std::move(bound)) {}

const runtime::InbetweenerRuntime& TransformerEncoderInitializer::transformer(const TaskContext* context) const {
  const std::string what = "initialiser '" + name_ + "'";
  if (!bound_ && !context) throw ModelMissingError(missing_inbetweener_message(what, kind_));
  return bound_ ? *bound_ : require_inbetweener(*context, kind_, what);
}

InitialGuess TransformerEncoderInitializer::initialize(const InitRequest& r) const {
  if (!r.window || !r.constraints) throw std::invalid_argument("InitRequest is incomplete");
  const Motion filled =
      inbetweener_fill(transformer(r.context), stage_, *r.window, *r.constraints, LongGapPolicy::Interpolate);
  return encode_window(r, filled);
}

std::optional<Motion> TransformerEncoderInitializer::fill_input(const Motion& input, const MotionConstraints& c,
                                                                const TaskContext& context) const {
  return inbetweener_fill(transformer(&context), stage_, input, c, LongGapPolicy::Interpolate);
}

std::vector<std::string> initializer_names() {
  std::vector<std::string> names = {"interp-encoder", "zero"};
  for (const InbetweenerKind& kind : inbetweener_kinds()) {
    for (const InbetweenerStage& stage : kind.stages) names.push_back(stage.name + "-encoder");
  }
  return names;
}

namespace {

std::shared_ptr<const LatentInitializer> make_named(const std::string& name, const TaskContext* context) {
  if (name == "interp-encoder") return std::make_shared<InterpolationEncoderInitializer>();
  if (name == "zero") return std::make_shared<ZeroInitializer>();
  for (const InbetweenerKind& kind : inbetweener_kinds()) {
    for (size_t stage = 0; stage < kind.stages.size(); ++stage) {
      if (name != kind.stages[stage].name + "-encoder") continue;
      std::shared_ptr<const runtime::InbetweenerRuntime> bound;
      if (context) {
        require_inbetweener(*context, kind.name, "initialiser '" + name + "'");
        bound = context->inbetweeners.at(kind.name);
      }
      return std::make_shared<TransformerEncoderInitializer>(name, kind.name, static_cast<int>(stage),
                                                             std::move(bound));
    }
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
