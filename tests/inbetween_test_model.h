// A tiny stand-in in-betweener for unit tests of the shared in-betweener code
// and the trainer, independent of the real architectures: one linear layer per
// frame from the normalised known pose and the known flags to the pose, plus
// an optional contact head. Kind "test-linear", registered on first use.
#pragma once

#include <ATen/ATen.h>

#include <map>
#include <memory>
#include <string>

#include "prior/inbetween/inbetweener.h"

namespace mf::test {

class LinearInbetweener : public InbetweenModel {
 public:
  LinearInbetweener(const std::map<std::string, double>& hp, const RigInfo& rig) : InbetweenModel(rig), hp_(hp) {
    hp_.emplace("window", 32);
    hp_.emplace("fps", 30);
    hp_.emplace("contacts", 1);
    const int64_t D = pose_size(), in = D + rig.num_joints() + 1;
    weight_ = (at::randn({D, in}) * 0.01).set_requires_grad(true);
    bias_ = at::zeros({D}).set_requires_grad(true);
    if (hp_.at("contacts") > 0) {
      contact_weight_ = (at::randn({rig.num_feet(), in}) * 0.01).set_requires_grad(true);
      contact_bias_ = at::zeros({rig.num_feet()}).set_requires_grad(true);
    }
  }
  std::string kind() const override { return "test-linear"; }
  std::vector<std::string> stage_names() const override { return {"linear"}; }
  std::map<std::string, double> hyperparameters() const override { return hp_; }
  std::string describe() const override { return "linear"; }
  InbetweenOutput forward(const InbetweenBatch& b) const override {
    const int J = rig().num_joints();
    at::Tensor mask = known_channel_mask(b.known, J);
    at::Tensor x = at::cat({(b.pose - stats().pose_mean) / stats().pose_std * mask, b.known}, -1);
    InbetweenOutput out;
    out.stages.push_back(at::linear(x, weight_, bias_) * stats().pose_std + stats().pose_mean);
    if (contact_weight_.defined()) out.contact_logits = at::linear(x, contact_weight_, contact_bias_);
    return out;
  }
  std::vector<std::pair<std::string, at::Tensor>> named_parameters() const override {
    std::vector<std::pair<std::string, at::Tensor>> p = {{"linear.weight", weight_}, {"linear.bias", bias_}};
    if (contact_weight_.defined()) {
      p.push_back({"contact.weight", contact_weight_});
      p.push_back({"contact.bias", contact_bias_});
    }
    return p;
  }
  void train(bool) override {}

 private:
  std::map<std::string, double> hp_;
  at::Tensor weight_, bias_, contact_weight_, contact_bias_;
};

inline void register_linear_inbetweener() {
  register_inbetweener_kind("test-linear", [](const std::map<std::string, double>& hp, const RigInfo& rig) {
    return std::unique_ptr<InbetweenModel>(new LinearInbetweener(hp, rig));
  });
}

}  // namespace mf::test
