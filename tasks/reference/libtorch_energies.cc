#include "tasks/reference/libtorch_energies.h"

#include <ATen/ATen.h>

#include "prior/model/nemf.h"
#include "tasks/reference/energies.h"
#include "tasks/reference/latent_energy.h"

namespace mf {
namespace {

// The energy of a window's problem under `weights` as a function of the codes.
CodeEnergy window_energy(const NemfModel& model, const WindowProblem& problem, const EnergyWeights& weights) {
  return [&model, &problem, weights](const at::Tensor& z_l, const at::Tensor& z_g) {
    return evaluate_energy(model, problem, weights, z_l, z_g);
  };
}

class TensorWindowEnergies final : public WindowEnergies {
 public:
  TensorWindowEnergies(const NemfModel& m, const RuntimeWindowProblem& p, const EnergyWeights& full_weights,
                       const EnergyWeights& keyed_weights)
      : model_(m),
        problem_(to_tensor_problem(p, m.rig().num_joints())),
        full_(window_energy(m, problem_, full_weights), m.config().zl, m.config().zg),
        keyed_(window_energy(m, problem_, keyed_weights), m.config().zl, m.config().zg) {}
  DirectLatentEnergy& full() override { return full_; }
  DirectLatentEnergy& keyed() override { return keyed_; }
  DecodedWindow decode(const Eigen::VectorXf& z_l, const Eigen::VectorXf& z_g) override {
    return decode_window(model_, problem_, codes_tensor(z_l), codes_tensor(z_g));
  }
  bool on_runtime() const override { return false; }

 private:
  const NemfModel& model_;
  const WindowProblem problem_;
  FlatLatentEnergy full_, keyed_;
};

class LibtorchEnergies final : public ReferenceEnergies {
 public:
  explicit LibtorchEnergies(std::shared_ptr<const NemfModel> model) : model_(std::move(model)) {}
  std::unique_ptr<WindowEnergies> latent_window(const RuntimeWindowProblem& problem, const EnergyWeights& full,
                                                const EnergyWeights& keyed) const override {
    return std::make_unique<TensorWindowEnergies>(*model_, problem, full, keyed);
  }

 private:
  std::shared_ptr<const NemfModel> model_;
};

}  // namespace

std::shared_ptr<const ReferenceEnergies> libtorch_energies(std::shared_ptr<const NemfModel> model) {
  return std::make_shared<LibtorchEnergies>(std::move(model));
}

}  // namespace mf
