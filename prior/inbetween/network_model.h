// What the transformer in-betweeners (two_stage.cc, citl.cc, keyframe_net.cc)
// share around their network: the configuration, the torch module, the
// parameters by name and the training mode. Internal to prior/inbetween/.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "prior/inbetween/inbetweener.h"
#include "prior/motion/errors.h"
#include "prior/util/module_parameters.h"

namespace mf {

/// An InbetweenModel around a module holder `Net` (TORCH_MODULE) built from a
/// `Config` that has to_map().
template <class Config, class Net>
class NetworkModel : public InbetweenModel {
 public:
  std::map<std::string, double> hyperparameters() const override { return config_.to_map(); }
  std::vector<std::pair<std::string, at::Tensor>> named_parameters() const override {
    return named_parameters_of(*net_);
  }
  void train(bool on) override { net_->train(on); }

 protected:
  NetworkModel(const Config& config, const RigInfo& rig, Net net)
      : InbetweenModel(rig), config_(config), net_(std::move(net)) {}

  Config config_;
  mutable Net net_;
};

/// A `Model` (a NetworkModel) of `config` on `rig`; InputError "<name>: the
/// rig has no joints" for an empty rig.
template <class Model, class Config>
std::unique_ptr<InbetweenModel> make_network_model(const std::string& name, const Config& config, const RigInfo& rig) {
  if (rig.num_joints() < 1) throw InputError(name + ": the rig has no joints");
  return std::make_unique<Model>(config, rig);
}

}  // namespace mf
