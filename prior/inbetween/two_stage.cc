#include "prior/inbetween/two_stage.h"

#include <ATen/ATen.h>

#include <cmath>
#include <sstream>

#include "prior/inbetween/network_model.h"
#include "prior/inbetween/transformer_blocks.h"
#include "prior/motion/errors.h"
#include "prior/util/module_parameters.h"

namespace mf {

namespace {

using blocks::Positions;
using blocks::Stage;

struct TwoStageNetImpl : torch::nn::Module {
  TwoStageNetImpl(const TwoStageConfig& c, int joints, int feet)
      : config(c), joints(joints), feet(feet), pose_size(joints * 6 + 3) {
    const int inputs = pose_size + joints + 1;
    context = register_module("context", Stage(c.trunk(), inputs, pose_size, true));
    detail = register_module("detail", Stage(c.trunk(), inputs, pose_size + feet, false));
    torch::NoGradGuard no_grad;
    detail->output->fc2->weight.mul_(0.1);  // the detail stage starts close to the identity
    detail->output->fc2->bias.zero_();
    if (c.interp_input) gate = context->register_parameter("gate", torch::zeros({1}));
  }

  // pose [B, T, D] raw; known [B, T, J + 1]; valid [B, T]; mean/std [D].
  InbetweenOutput forward(const at::Tensor& pose, const at::Tensor& known_in, const at::Tensor& valid,
                          const at::Tensor& mean, const at::Tensor& scale) {
    const int64_t J = joints, D = pose_size;
    at::Tensor known = known_in * valid.unsqueeze(-1);
    at::Tensor channel_known = known_channel_mask(known, joints) > 0.5;  // [B, T, D]
    at::Tensor normalised = (pose - mean) / scale;
    at::Tensor rotations = config.interp_input
                               ? interpolated_rotations(normalised.narrow(-1, 0, 6 * J), known)
                               : at::where(channel_known.narrow(-1, 0, 6 * J), normalised.narrow(-1, 0, 6 * J),
                                           at::zeros({1}, pose.options()));
    at::Tensor root_known = known.select(-1, J) > 0.5;
    at::Tensor root_in = blocks::interpolate_known(pose.narrow(-1, 6 * J, 3), root_known);
    at::Tensor root = (root_in - mean.narrow(0, 6 * J, 3)) / scale.narrow(0, 6 * J, 3);
    at::Tensor x = at::cat({rotations, root}, -1);  // normalised input; exact where known

    at::Tensor key = known.amax(-1) > 0.5;
    at::Tensor key_mask = blocks::additive_mask(key, pose.options());
    at::Tensor valid_mask = blocks::additive_mask(valid > 0.5, pose.options());
    Positions positions = blocks::make_positions(pose.size(1), config.window, pose.options());

    at::Tensor key_encoding = blocks::key_features(key, config.window);
    at::Tensor context_out = context->forward(at::cat({x, known}, -1), key_encoding, key_mask, positions);  // normalised
    if (config.interp_input) context_out = x + kGateScale * gate * context_out;
    at::Tensor mixed = at::where(channel_known, x, context_out);
    at::Tensor detail_out = detail->forward(at::cat({mixed, known}, -1), at::Tensor(), valid_mask, positions);

    InbetweenOutput out;
    out.stages.push_back(context_out * scale + mean);
    out.stages.push_back((mixed + detail_out.narrow(-1, 0, D)) * scale + mean);
    out.contact_logits = detail_out.narrow(-1, D, feet);
    return out;
  }

  // Each joint's normalised 6D channels [B, T, J * 6], at frames where that
  // joint is unknown linearly interpolated between its nearest known frames.
  at::Tensor interpolated_rotations(const at::Tensor& rotations, const at::Tensor& known) const {
    const int64_t B = rotations.size(0), T = rotations.size(1), J = joints;
    at::Tensor per_joint = rotations.reshape({B, T, J, 6}).permute({0, 2, 1, 3}).reshape({B * J, T, 6});
    at::Tensor joint_known = known.narrow(-1, 0, J).permute({0, 2, 1}).reshape({B * J, T}) > 0.5;
    at::Tensor filled = blocks::interpolate_known(per_joint, joint_known);
    return filled.reshape({B, J, T, 6}).permute({0, 2, 1, 3}).reshape({B, T, J * 6});
  }

  TwoStageConfig config;
  int joints, feet, pose_size;
  Stage context{nullptr}, detail{nullptr};
  at::Tensor gate;  // interp_input: the context stage's correction scale / kGateScale, 0 at the start
  // Adam moves a parameter by about the learning rate per step; the scale lets
  // the gate open within a few hundred steps.
  static constexpr double kGateScale = 10.0;
};
TORCH_MODULE(TwoStageNet);

class TwoStageModel final : public NetworkModel<TwoStageConfig, TwoStageNet> {
 public:
  TwoStageModel(const TwoStageConfig& config, const RigInfo& rig)
      : NetworkModel(config, rig, TwoStageNet(config, rig.num_joints(), rig.num_feet())) {}

  std::string kind() const override { return kTwoStageKind; }
  std::vector<std::string> stage_names() const override { return {"context", "detail"}; }
  std::string describe() const override {
    std::ostringstream s;
    s << "twostage: context " << config_.layers << "x" << config_.width << ", detail " << config_.layers << "x"
      << config_.width << ", " << config_.heads << " heads, ffn " << config_.ffn << ", window " << config_.window
      << " frames at " << config_.fps << " fps";
    if (config_.interp_input) s << ", on interpolated input";
    return s.str();
  }

  InbetweenOutput forward(const InbetweenBatch& batch) const override {
    const Normalisation n = checked_normalisation(batch, config_.window, "twostage");
    const int64_t D = pose_size();
    return net_->forward(batch.pose.to(at::kFloat), batch.known.to(n.options), batch.valid.to(n.options),
                         n.mean.reshape({D}), n.scale.reshape({D}));
  }
};

}  // namespace

std::unique_ptr<InbetweenModel> make_two_stage(const std::map<std::string, double>& hyperparameters,
                                               const RigInfo& rig) {
  return make_network_model<TwoStageModel>("twostage", parse_two_stage_config(hyperparameters), rig);
}

int64_t two_stage_parameter_count(const std::map<std::string, double>& hyperparameters, const RigInfo& rig) {
  const TwoStageConfig c = parse_two_stage_config(hyperparameters);
  const int pose_size = rig.num_joints() * 6 + 3, inputs = pose_size + rig.num_joints() + 1;
  return blocks::stage_parameter_count(c.trunk(), inputs, pose_size, true) +
         blocks::stage_parameter_count(c.trunk(), inputs, pose_size + rig.num_feet(), false) + c.interp_input;
}

InbetweenNetwork two_stage_network() { return {make_two_stage, two_stage_parameter_count}; }

}  // namespace mf
