// The Eigen runtime's energy of a window (tasks/latent/runtime_energy.h) as
// the optimiser's DirectLatentEnergy (tasks/latent/latent_optimizer.h): a
// function of x = [z_l, z_g].
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "tasks/latent/latent_optimizer.h"
#include "tasks/latent/runtime_energy.h"

namespace mf {

/// An energy of the codes (z_l [zl], z_g [zg]) on the Eigen runtime: its
/// terms and, when g_zl and g_zg are not null, its gradient.
using RuntimeCodeEnergy =
    std::function<RuntimeEnergyTerms(const Eigen::Ref<const Eigen::VectorXf>& z_l,
                                     const Eigen::Ref<const Eigen::VectorXf>& z_g, Eigen::VectorXf* g_zl,
                                     Eigen::VectorXf* g_zg)>;

/// A runtime energy of the codes as a function of x = [z_l, z_g] (zl + zg
/// values, rounded to float as the tensor energy's x is), as
/// FlatLatentEnergy (tasks/reference/latent_energy.h) is libtorch's.
class RuntimeLatentEnergy final : public DirectLatentEnergy {
 public:
  RuntimeLatentEnergy(RuntimeCodeEnergy energy, int zl, int zg);
  /// RuntimeEnergy::evaluate() on one window's problem under `weights`;
  /// `energy` and `problem` must outlive it.
  RuntimeLatentEnergy(RuntimeEnergy& energy, const RuntimeWindowProblem& problem, const EnergyWeights& weights, int zl,
                      int zg);

  int size() const override { return zl_ + zg_; }
  double evaluate(const double* x, double* gradient) override;
  std::vector<std::pair<std::string, double>> terms(const double* x, double* total) override;

 private:
  RuntimeEnergyTerms run(const double* x, bool gradient);

  RuntimeCodeEnergy energy_;
  int zl_, zg_;
  Eigen::VectorXf x_, g_zl_, g_zg_;
};

}  // namespace mf
