#include "tasks/latent/runtime_latent_energy.h"

#include <utility>
#include <vector>

namespace mf {

RuntimeLatentEnergy::RuntimeLatentEnergy(RuntimeCodeEnergy energy, int zl, int zg)
    : energy_(std::move(energy)), zl_(zl), zg_(zg), x_(zl + zg) {}

RuntimeLatentEnergy::RuntimeLatentEnergy(RuntimeEnergy& energy, const RuntimeWindowProblem& problem,
                                         const EnergyWeights& weights, int zl, int zg)
    : RuntimeLatentEnergy(
          [&energy, &problem, weights](const Eigen::Ref<const Eigen::VectorXf>& z_l,
                                       const Eigen::Ref<const Eigen::VectorXf>& z_g, Eigen::VectorXf* g_zl,
                                       Eigen::VectorXf* g_zg) {
            return energy.evaluate(problem, weights, z_l, z_g, g_zl, g_zg);
          },
          zl, zg) {}

RuntimeEnergyTerms RuntimeLatentEnergy::run(const double* x, bool gradient) {
  for (int i = 0; i < size(); ++i) x_[i] = static_cast<float>(x[i]);
  return energy_(x_.head(zl_), x_.tail(zg_), gradient ? &g_zl_ : nullptr, gradient ? &g_zg_ : nullptr);
}

double RuntimeLatentEnergy::evaluate(const double* x, double* gradient) {
  const double total = run(x, gradient != nullptr).total;
  if (gradient) {
    for (int i = 0; i < zl_; ++i) gradient[i] = g_zl_[i];
    for (int i = 0; i < zg_; ++i) gradient[zl_ + i] = g_zg_[i];
  }
  return total;
}

std::vector<std::pair<std::string, double>> RuntimeLatentEnergy::terms(const double* x, double* total) {
  RuntimeEnergyTerms t = run(x, false);
  *total = t.total;
  return std::move(t.terms);
}

}  // namespace mf
