#include "tasks/latent/runtime_problem.h"

#include <ATen/ATen.h>

#include <utility>
#include <vector>

namespace mf {
namespace {

// The values of an int64 tensor of n entries.
std::vector<int> ints_of(const at::Tensor& t, int n) {
  if (n == 0) return {};
  const at::Tensor c = t.to(at::kLong).contiguous();
  return std::vector<int>(c.data_ptr<int64_t>(), c.data_ptr<int64_t>() + n);
}

}  // namespace

RuntimeWindowProblem to_runtime_problem(const WindowProblem& problem, int joints) {
  RuntimeWindowProblem p;
  const int K = problem.num_keys(), J = joints;
  p.length = problem.length;
  p.anchor = problem.anchor;
  p.key_frames = ints_of(problem.key_frames, K);
  p.key_rotations = rows_of(problem.key_rotations, K, J * 9);
  p.key_rotation_mask = rows_of(problem.key_rotation_mask, K, J);
  p.key_positions = rows_of(problem.key_positions, K, J * 3);
  p.key_position_mask = rows_of(problem.key_position_mask, K, J);
  p.key_root = rows_of(problem.key_root, K, 3);
  p.key_root_mask = rows_of(problem.key_root_mask, K, 1).col(0);
  const int E = problem.num_effectors(), P = problem.num_pin_steps(), R = problem.num_trajectory();
  p.effector_frames = ints_of(problem.effector_frames, E);
  p.effector_joints = ints_of(problem.effector_joints, E);
  p.effector_targets = rows_of(problem.effector_targets, E, 3);
  p.effector_weights = rows_of(problem.effector_weights, E, 1).col(0);
  p.pin_from = ints_of(problem.pin_from, P);
  p.pin_to = ints_of(problem.pin_to, P);
  p.trajectory_frames = ints_of(problem.trajectory_frames, R);
  p.trajectory_ground = rows_of(problem.trajectory_ground, R, 2);
  p.trajectory_forward = rows_of(problem.trajectory_forward, R, 2);
  return p;
}

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
