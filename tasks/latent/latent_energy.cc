#include "tasks/latent/latent_energy.h"

#include <ATen/ATen.h>

namespace mf {

FlatLatentEnergy::FlatLatentEnergy(CodeEnergy energy, int zl, int zg) : energy_(std::move(energy)), zl_(zl), zg_(zg) {}

EnergyTerms FlatLatentEnergy::operator()(const at::Tensor& x) const {
  return energy_(x.narrow(0, 0, zl_).view({1, zl_}), x.narrow(0, zl_, zg_).view({1, zg_}));
}

LatentEnergy FlatLatentEnergy::total() const {
  return [this](const at::Tensor& x) { return (*this)(x).total; };
}

double FlatLatentEnergy::cost(const at::Tensor& x) const {
  at::NoGradGuard no_grad;
  return (*this)(x).total.item<double>();
}

std::vector<std::pair<std::string, double>> FlatLatentEnergy::terms(const at::Tensor& x, double* total) const {
  at::NoGradGuard no_grad;
  EnergyTerms e = (*this)(x);
  std::vector<std::pair<std::string, double>> out;
  for (const auto& t : e.terms) out.emplace_back(t.first, t.second.item<double>());
  *total = e.total.item<double>();
  return out;
}

at::Tensor FlatLatentEnergy::join(const at::Tensor& z_l, const at::Tensor& z_g) const {
  return at::cat({z_l.reshape({zl_}), z_g.reshape({zg_})}).to(at::kFloat).detach();
}

at::Tensor FlatLatentEnergy::z_l(const at::Tensor& x) const { return x.narrow(0, 0, zl_).reshape({1, zl_}).clone(); }

at::Tensor FlatLatentEnergy::z_g(const at::Tensor& x) const { return x.narrow(0, zl_, zg_).reshape({1, zg_}).clone(); }

}  // namespace mf
