// The bridge between the tensor side of the latent solvers and the Eigen
// runtime's energy (tasks/latent/runtime_energy.h): the one conversion from
// the tensor WindowProblem (tasks/latent/energies.h) to the runtime's
// RuntimeWindowProblem, so that a solver can evaluate the same window either
// way, and the runtime's energy as the optimiser's DirectLatentEnergy
// (tasks/latent/latent_optimizer.h).
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "tasks/latent/energies.h"
#include "tasks/latent/latent_optimizer.h"
#include "tasks/latent/runtime_energy.h"

namespace mf {

/// The problem's constraints copied to float matrices (one row per key,
/// effector or trajectory row) and index vectors, for a rig of `joints` joints.
RuntimeWindowProblem to_runtime_problem(const WindowProblem& problem, int joints);

/// RuntimeEnergy::evaluate() on one window's problem under `weights` as a
/// function of x = [z_l, z_g] (zl + zg values, rounded to float as the
/// tensor energy's x is), as FlatLatentEnergy (tasks/latent/latent_energy.h)
/// is the tensor energy's. `energy` and `problem` must outlive it.
class RuntimeLatentEnergy final : public DirectLatentEnergy {
 public:
  RuntimeLatentEnergy(RuntimeEnergy& energy, const RuntimeWindowProblem& problem, const EnergyWeights& weights, int zl,
                      int zg);

  int size() const override { return zl_ + zg_; }
  double evaluate(const double* x, double* gradient) override;
  std::vector<std::pair<std::string, double>> terms(const double* x, double* total) override;

 private:
  RuntimeEnergyTerms run(const double* x, bool gradient);

  RuntimeEnergy* energy_;
  const RuntimeWindowProblem* problem_;
  EnergyWeights weights_;
  int zl_, zg_;
  Eigen::VectorXf x_, g_zl_, g_zg_;
};

}  // namespace mf
