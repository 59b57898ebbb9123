#include "tasks/reference/latent_energy.h"

#include <torch/csrc/autograd/autograd.h>

#include <ATen/ATen.h>

namespace mf {
namespace {

at::Tensor x_tensor(const double* x, int n) {
  return at::from_blob(const_cast<double*>(x), {n}, at::kDouble).to(at::kFloat);
}

}  // namespace

FlatLatentEnergy::FlatLatentEnergy(CodeEnergy energy, int zl, int zg) : energy_(std::move(energy)), zl_(zl), zg_(zg) {}

EnergyTerms FlatLatentEnergy::operator()(const at::Tensor& x) const {
  return energy_(x.narrow(0, 0, zl_).view({1, zl_}), x.narrow(0, zl_, zg_).view({1, zg_}));
}

double FlatLatentEnergy::evaluate(const double* x, double* gradient) {
  const at::Tensor leaf = x_tensor(x, size());
  if (!gradient) {
    at::NoGradGuard no_grad;
    return (*this)(leaf).total.item<double>();
  }
  leaf.requires_grad_(true);
  const at::Tensor e = (*this)(leaf).total;
  const at::Tensor g = torch::autograd::grad({e}, {leaf})[0].to(at::kDouble).contiguous();
  std::copy(g.data_ptr<double>(), g.data_ptr<double>() + size(), gradient);
  return e.item<double>();
}

double FlatLatentEnergy::cost(const Eigen::VectorXd& x) { return evaluate(x.data(), nullptr); }

std::vector<std::pair<std::string, double>> FlatLatentEnergy::terms(const double* x, double* total) {
  at::NoGradGuard no_grad;
  EnergyTerms e = (*this)(x_tensor(x, size()));
  std::vector<std::pair<std::string, double>> out;
  for (const auto& t : e.terms) out.emplace_back(t.first, t.second.item<double>());
  *total = e.total.item<double>();
  return out;
}

at::Tensor codes_tensor(const Eigen::Ref<const Eigen::VectorXf>& codes) {
  const int64_t n = codes.size();
  return at::from_blob(const_cast<float*>(codes.data()), {1, n}, at::kFloat).clone();
}

Eigen::VectorXf codes_vector(const at::Tensor& codes) {
  const at::Tensor c = codes.detach().to(at::kFloat).contiguous().reshape({-1});
  return Eigen::Map<const Eigen::VectorXf>(c.data_ptr<float>(), c.numel());
}

runtime::MatrixRXf rows_of(const at::Tensor& t, int64_t rows, int64_t cols) {
  if (rows == 0) return runtime::MatrixRXf(0, cols);
  const at::Tensor c = t.detach().to(at::kFloat).contiguous().reshape({rows, cols});
  return Eigen::Map<const runtime::MatrixRXf>(c.data_ptr<float>(), rows, cols);
}

}  // namespace mf
