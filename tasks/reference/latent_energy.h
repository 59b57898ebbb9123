// Energies of the prior's latent codes on libtorch, as the optimiser sees
// them. A libtorch energy of the codes (z_l [1, zl], z_g [1, zg]) is a sum
// of named, weighted terms (EnergyTerms); FlatLatentEnergy turns it into a
// DirectLatentEnergy of one flat vector x = [z_l, z_g], the variable of
// tasks/latent/latent_optimizer.h, with its gradient from autograd. The Eigen
// runtime's energies (tasks/latent/runtime_latent_energy.h) are DirectLatentEnergy
// themselves; this adapter serves the libtorch energies the runtime is
// checked against (tasks/reference/).
#pragma once

#include <ATen/core/Tensor.h>
#include <Eigen/Core>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "prior/runtime/tensor_ops.h"
#include "tasks/latent/latent_optimizer.h"

namespace mf {

/// An energy's weighted terms and their sum.
struct EnergyTerms {
  at::Tensor total;                                      ///< scalar
  std::vector<std::pair<std::string, at::Tensor>> terms;  ///< active terms, weighted
};

/// An energy of the codes z_l [1, zl] and z_g [1, zg], differentiable in them.
using CodeEnergy = std::function<EnergyTerms(const at::Tensor& z_l, const at::Tensor& z_g)>;

/// A CodeEnergy as a function of x = [z_l, z_g]: x rounded to float, the
/// gradient from autograd.
class FlatLatentEnergy final : public DirectLatentEnergy {
 public:
  FlatLatentEnergy(CodeEnergy energy, int zl, int zg);

  int size() const override { return zl_ + zg_; }
  double evaluate(const double* x, double* gradient) override;
  std::vector<std::pair<std::string, double>> terms(const double* x, double* total) override;
  /// The total at x, without gradient.
  double cost(const Eigen::VectorXd& x);
  /// The terms at x ([zl + zg] float tensor): z_l = x[0, zl), z_g = x[zl, zl + zg) (views of x).
  EnergyTerms operator()(const at::Tensor& x) const;

 private:
  CodeEnergy energy_;
  int zl_, zg_;
};

/// Codes as a [1, n] float tensor, and a tensor's values as codes.
at::Tensor codes_tensor(const Eigen::Ref<const Eigen::VectorXf>& codes);
Eigen::VectorXf codes_vector(const at::Tensor& codes);
/// A tensor's values (detached, as float) as a row-major matrix of `rows`
/// rows (rows = 0: an empty matrix of `cols` columns).
runtime::MatrixRXf rows_of(const at::Tensor& t, int64_t rows, int64_t cols);

}  // namespace mf
