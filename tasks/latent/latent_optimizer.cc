#include "tasks/latent/latent_optimizer.h"

#include <ceres/first_order_function.h>
#include <ceres/gradient_problem.h>
#include <ceres/gradient_problem_solver.h>
#include <ceres/iteration_callback.h>
#include <torch/csrc/autograd/autograd.h>

#include <ATen/ATen.h>
#include <algorithm>
#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <utility>

#include "prior/motion/errors.h"

namespace mf {
namespace {

// Cost and gradient at x (a fresh leaf is made from it).
double with_gradient(const LatentEnergy& energy, const at::Tensor& x, at::Tensor* gradient) {
  at::Tensor leaf = x.detach().clone().requires_grad_(true);
  at::Tensor e = energy(leaf);
  *gradient = torch::autograd::grad({e}, {leaf})[0];
  return e.item<double>();
}

// The cost at x ([n]) and, when `gradient` is not null, its gradient there.
using Evaluation = std::function<double(const double* x, double* gradient)>;

// A tensor energy as an Evaluation: x rounded to float, the gradient from autograd.
Evaluation tensor_evaluation(const LatentEnergy& energy, int n) {
  return [&energy, n](const double* parameters, double* gradient) {
    at::Tensor x = at::from_blob(const_cast<double*>(parameters), {n}, at::kDouble).to(at::kFloat);
    if (!gradient) {
      at::NoGradGuard no_grad;
      return energy(x).item<double>();
    }
    at::Tensor g;
    const double cost = with_gradient(energy, x, &g);
    at::Tensor gd = g.to(at::kDouble).contiguous();
    std::copy(gd.data_ptr<double>(), gd.data_ptr<double>() + n, gradient);
    return cost;
  };
}

class CeresEnergy final : public ceres::FirstOrderFunction {
 public:
  CeresEnergy(Evaluation evaluate, int n) : evaluate_(std::move(evaluate)), n_(n) {}
  int NumParameters() const override { return n_; }
  bool Evaluate(const double* parameters, double* cost, double* gradient) const override {
    ++evaluations_;
    try {
      *cost = evaluate_(parameters, gradient);
      if (!std::isfinite(*cost)) return false;
      for (int i = 0; gradient && i < n_; ++i) {
        if (!std::isfinite(gradient[i])) return false;
      }
      return true;
    } catch (...) {
      if (!error_) error_ = std::current_exception();
      return false;
    }
  }
  int evaluations() const { return evaluations_; }
  std::exception_ptr error() const { return error_; }

 private:
  Evaluation evaluate_;
  int n_;
  mutable int evaluations_ = 0;
  mutable std::exception_ptr error_;
};

class ProgressCallback final : public ceres::IterationCallback {
 public:
  ProgressCallback(const TaskContext& ctx, int offset, int total) : ctx_(ctx), offset_(offset), total_(total) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    try {
      ctx_.report({offset_ + s.iteration, total_, s.cost});
    } catch (const CancelledError&) {
      cancelled = true;
      return ceres::SOLVER_ABORT;
    }
    return ceres::SOLVER_CONTINUE;
  }
  bool cancelled = false;

 private:
  const TaskContext& ctx_;
  int offset_, total_;
};

at::Tensor lbfgs(Evaluation evaluate, const at::Tensor& x0, const LatentOptimizerSettings& o, const TaskContext& ctx,
                 int offset, int total, LatentOptimizerStats* stats) {
  const int n = static_cast<int>(x0.numel());
  std::vector<double> x(n);
  {
    at::Tensor d = x0.to(at::kDouble).contiguous();
    std::copy(d.data_ptr<double>(), d.data_ptr<double>() + n, x.begin());
  }
  auto* function = new CeresEnergy(std::move(evaluate), n);
  ceres::GradientProblem problem(function);  // takes ownership
  ceres::GradientProblemSolver::Options options;
  options.line_search_direction_type = ceres::LBFGS;
  options.max_lbfgs_rank = o.lbfgs_rank;
  options.use_approximate_eigenvalue_bfgs_scaling = o.lbfgs_eigenvalue_scaling;
  options.max_num_iterations = o.max_iterations;
  options.function_tolerance = o.function_tolerance;
  options.gradient_tolerance = o.gradient_tolerance;
  options.parameter_tolerance = o.parameter_tolerance;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  ProgressCallback progress(ctx, offset, total);
  options.callbacks.push_back(&progress);
  std::string why;
  if (!options.IsValid(&why)) throw InputError("invalid L-BFGS options: " + why);
  ceres::GradientProblemSolver::Summary s;
  ceres::Solve(options, problem, x.data(), &s);
  if (progress.cancelled) throw CancelledError();
  if (function->error()) std::rethrow_exception(function->error());
  stats->iterations = std::max(0, static_cast<int>(s.iterations.size()) - 1);
  stats->evaluations = function->evaluations();
  stats->converged = s.termination_type == ceres::CONVERGENCE;
  stats->message = s.message;
  return at::from_blob(x.data(), {n}, at::kDouble).to(at::kFloat);
}

at::Tensor adam(const LatentEnergy& energy, const at::Tensor& x0, const LatentOptimizerSettings& o,
                const TaskContext& ctx, int offset, int total, LatentOptimizerStats* stats) {
  if (!(o.adam_lr > 0) || o.adam_decay_every < 1 || !(o.adam_decay > 0) || o.adam_patience < 1)
    throw InputError("invalid Adam settings");
  const double b1 = 0.9, b2 = 0.999, eps = 1e-8;
  at::Tensor x = x0.to(at::kFloat).clone();
  at::Tensor m = at::zeros_like(x), v = at::zeros_like(x);
  at::Tensor best_x = x.clone();
  double best = std::numeric_limits<double>::infinity();
  std::vector<double> history;
  stats->message = "iteration cap reached";
  int it = 0;
  for (; it < o.max_iterations; ++it) {
    at::Tensor g;
    const double f = with_gradient(energy, x, &g);
    ++stats->evaluations;
    if (!std::isfinite(f)) {
      stats->message = "non-finite energy";
      break;
    }
    if (f < best) {
      best = f;
      best_x = x.clone();
    }
    history.push_back(best);
    ctx.report({offset + it, total, f});
    if (it >= o.adam_patience) {
      const double before = history[it - o.adam_patience];
      if (before - best <= o.adam_tolerance * std::abs(before)) {
        stats->converged = true;
        stats->message = "converged: the energy improved by less than the tolerance over the patience window";
        ++it;
        break;
      }
    }
    const double lr = o.adam_lr * std::pow(o.adam_decay, it / o.adam_decay_every);
    at::NoGradGuard no_grad;
    m.mul_(b1).add_(g, 1 - b1);
    v.mul_(b2).addcmul_(g, g, 1 - b2);
    const double c1 = 1 - std::pow(b1, it + 1), c2 = 1 - std::pow(b2, it + 1);
    x = x - (m / c1) / ((v / c2).sqrt() + eps) * lr;
  }
  stats->iterations = it;
  return best_x;
}

}  // namespace

std::string LatentOptimizerSettings::validate() const {
  std::ostringstream e;
  if (max_iterations < 0) e << "max_iterations must be >= 0; ";
  if (lbfgs_rank < 1) e << "lbfgs_rank must be >= 1; ";
  if (!(function_tolerance >= 0) || !(gradient_tolerance >= 0) || !(parameter_tolerance >= 0))
    e << "tolerances must be >= 0; ";
  if (!(adam_lr > 0) || !std::isfinite(adam_lr)) e << "adam_lr must be positive; ";
  if (adam_decay_every < 1 || !(adam_decay > 0 && adam_decay <= 1)) e << "bad Adam decay; ";
  if (!(adam_tolerance >= 0) || adam_patience < 1) e << "bad Adam convergence settings; ";
  return e.str();
}

at::Tensor minimize_latent(const LatentEnergy& energy, const at::Tensor& x0, const LatentOptimizerSettings& settings,
                           const TaskContext& ctx, LatentOptimizerStats* stats, int iteration_offset,
                           int iteration_total) {
  *stats = LatentOptimizerStats{};
  const int total = iteration_total > 0 ? iteration_total : settings.max_iterations;
  return settings.optimizer == LatentOptimizer::Lbfgs
             ? lbfgs(tensor_evaluation(energy, static_cast<int>(x0.numel())), x0, settings, ctx, iteration_offset,
                     total, stats)
             : adam(energy, x0, settings, ctx, iteration_offset, total, stats);
}

at::Tensor minimize_latent(DirectLatentEnergy& energy, const at::Tensor& x0, const LatentOptimizerSettings& settings,
                           const TaskContext& ctx, LatentOptimizerStats* stats, int iteration_offset,
                           int iteration_total) {
  if (settings.optimizer != LatentOptimizer::Lbfgs)
    throw InputError("an energy evaluated without tensors is minimised with L-BFGS only");
  if (x0.numel() != energy.size())
    throw InputError("the start has " + std::to_string(x0.numel()) + " values, the energy " +
                     std::to_string(energy.size()));
  *stats = LatentOptimizerStats{};
  const int total = iteration_total > 0 ? iteration_total : settings.max_iterations;
  return lbfgs([&energy](const double* x, double* gradient) { return energy.evaluate(x, gradient); }, x0, settings,
               ctx, iteration_offset, total, stats);
}

}  // namespace mf
