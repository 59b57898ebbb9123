#include "tasks/latent/runtime_problem.h"

#include <ATen/ATen.h>

namespace mf {
namespace {

// A float tensor of `rows` rows as a row-major matrix of `cols` columns.
runtime::MatrixRXf matrix_of(const at::Tensor& t, int rows, int cols) {
  if (rows == 0) return runtime::MatrixRXf(0, cols);
  const at::Tensor c = t.detach().to(at::kFloat).contiguous().reshape({rows, cols});
  return Eigen::Map<const runtime::MatrixRXf>(c.data_ptr<float>(), rows, cols);
}

}  // namespace

RuntimeWindowProblem to_runtime_problem(const WindowProblem& problem, int joints) {
  RuntimeWindowProblem p;
  const int K = problem.num_keys(), J = joints;
  p.length = problem.length;
  p.anchor = problem.anchor;
  if (K > 0) {
    const at::Tensor frames = problem.key_frames.to(at::kLong).contiguous();
    p.key_frames.assign(frames.data_ptr<int64_t>(), frames.data_ptr<int64_t>() + K);
  }
  p.key_rotations = matrix_of(problem.key_rotations, K, J * 9);
  p.key_rotation_mask = matrix_of(problem.key_rotation_mask, K, J);
  p.key_positions = matrix_of(problem.key_positions, K, J * 3);
  p.key_position_mask = matrix_of(problem.key_position_mask, K, J);
  p.key_root = matrix_of(problem.key_root, K, 3);
  p.key_root_mask = matrix_of(problem.key_root_mask, K, 1).col(0);
  p.num_effectors = problem.num_effectors();
  p.num_pin_steps = problem.num_pin_steps();
  p.num_trajectory = problem.num_trajectory();
  return p;
}

RuntimeLatentEnergy::RuntimeLatentEnergy(RuntimeEnergy& energy, const RuntimeWindowProblem& problem,
                                         const EnergyWeights& weights, int zl, int zg)
    : energy_(&energy), problem_(&problem), weights_(weights), zl_(zl), zg_(zg), x_(zl + zg) {}

RuntimeEnergyTerms RuntimeLatentEnergy::run(const double* x, bool gradient) {
  for (int i = 0; i < size(); ++i) x_[i] = static_cast<float>(x[i]);
  return energy_->evaluate(*problem_, weights_, x_.head(zl_), x_.tail(zg_), gradient ? &g_zl_ : nullptr,
                           gradient ? &g_zg_ : nullptr);
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
