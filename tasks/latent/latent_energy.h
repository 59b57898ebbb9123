// Energies of the prior's latent codes as the optimiser sees them. Every
// latent-space task (the latent solvers, re-navigation) defines an energy of
// the codes (z_l [1, zl], z_g [1, zg]) as a sum of named, weighted terms
// (EnergyTerms); FlatLatentEnergy turns it into a function of one flat vector
// x = [z_l, z_g], the variable of tasks/latent/latent_optimizer.h, and reads the
// terms out for reports.
#pragma once

#include <ATen/core/Tensor.h>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace mf {

/// An energy's weighted terms and their sum.
struct EnergyTerms {
  at::Tensor total;                                      ///< scalar
  std::vector<std::pair<std::string, at::Tensor>> terms;  ///< active terms, weighted
};

/// An energy of x ([n] float): a differentiable scalar tensor.
using LatentEnergy = std::function<at::Tensor(const at::Tensor& x)>;

/// An energy of the codes z_l [1, zl] and z_g [1, zg], differentiable in them.
using CodeEnergy = std::function<EnergyTerms(const at::Tensor& z_l, const at::Tensor& z_g)>;

/// A CodeEnergy as a function of x = [z_l, z_g] ([zl + zg] float).
class FlatLatentEnergy {
 public:
  FlatLatentEnergy(CodeEnergy energy, int zl, int zg);

  /// The terms at x: z_l = x[0, zl), z_g = x[zl, zl + zg) (views of x).
  EnergyTerms operator()(const at::Tensor& x) const;
  /// The total, for minimize_latent(); it refers to this object.
  LatentEnergy total() const;
  /// The total at x, without gradient.
  double cost(const at::Tensor& x) const;
  /// Each term's value and (in *total) their sum at x, without gradient.
  std::vector<std::pair<std::string, double>> terms(const at::Tensor& x, double* total) const;

  /// x for the codes z_l, z_g (any shapes with zl and zg values; float, detached).
  at::Tensor join(const at::Tensor& z_l, const at::Tensor& z_g) const;
  /// The codes in x, [1, zl] and [1, zg] (copies).
  at::Tensor z_l(const at::Tensor& x) const;
  at::Tensor z_g(const at::Tensor& x) const;

 private:
  CodeEnergy energy_;
  int zl_, zg_;
};

}  // namespace mf
