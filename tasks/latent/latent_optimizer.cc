#include "tasks/latent/latent_optimizer.h"

#include <ceres/first_order_function.h>
#include <ceres/gradient_problem.h>
#include <ceres/gradient_problem_solver.h>
#include <ceres/iteration_callback.h>

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

// The cost at x ([n]) and, when `gradient` is not null, its gradient there.
using Evaluation = std::function<double(const double* x, double* gradient)>;

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

Eigen::VectorXd lbfgs(Evaluation evaluate, const Eigen::VectorXd& x0, const LatentOptimizerSettings& o,
                      const TaskContext& ctx, int offset, int total, LatentOptimizerStats* stats) {
  const int n = static_cast<int>(x0.size());
  Eigen::VectorXd x = x0;
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
  return x;
}

// Whether the best energy improved by less than the tolerance over the
// patience window ending at iteration `it`.
bool adam_converged(const std::vector<double>& best_so_far, int it, const LatentOptimizerSettings& o) {
  if (it < o.adam_patience) return false;
  const double before = best_so_far[it - o.adam_patience];
  return before - best_so_far[it] <= o.adam_tolerance * std::abs(before);
}

Eigen::VectorXd adam(DirectLatentEnergy& energy, const Eigen::VectorXd& x0, const LatentOptimizerSettings& o,
                     const TaskContext& ctx, int offset, int total, LatentOptimizerStats* stats) {
  if (!(o.adam_lr > 0) || o.adam_decay_every < 1 || !(o.adam_decay > 0) || o.adam_patience < 1)
    throw InputError("invalid Adam settings");
  const double b1 = 0.9, b2 = 0.999, eps = 1e-8;
  Eigen::VectorXd x = x0, best_x = x0, g(x0.size());
  Eigen::ArrayXd m = Eigen::ArrayXd::Zero(x0.size()), v = m;
  double best = std::numeric_limits<double>::infinity();
  std::vector<double> history;
  stats->message = "iteration cap reached";
  int it = 0;
  for (; it < o.max_iterations; ++it) {
    const double f = energy.evaluate(x.data(), g.data());
    ++stats->evaluations;
    if (!std::isfinite(f) || !g.allFinite()) {
      stats->message = "non-finite energy";
      break;
    }
    if (f < best) {
      best = f;
      best_x = x;
    }
    history.push_back(best);
    ctx.report({offset + it, total, f});
    if (adam_converged(history, it, o)) {
      stats->converged = true;
      stats->message = "converged: the energy improved by less than the tolerance over the patience window";
      ++it;
      break;
    }
    const double lr = o.adam_lr * std::pow(o.adam_decay, it / o.adam_decay_every);
    m = b1 * m + (1 - b1) * g.array();
    v = b2 * v + (1 - b2) * g.array().square();
    const double c1 = 1 - std::pow(b1, it + 1), c2 = 1 - std::pow(b2, it + 1);
    x -= (lr * (m / c1) / ((v / c2).sqrt() + eps)).matrix();
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

Eigen::VectorXd minimize_latent(DirectLatentEnergy& energy, const Eigen::VectorXd& x0,
                                const LatentOptimizerSettings& settings, const TaskContext& ctx,
                                LatentOptimizerStats* stats, int iteration_offset, int iteration_total) {
  if (x0.size() != energy.size())
    throw InputError("the start has " + std::to_string(x0.size()) + " values, the energy " +
                     std::to_string(energy.size()));
  *stats = LatentOptimizerStats{};
  const int total = iteration_total > 0 ? iteration_total : settings.max_iterations;
  if (settings.optimizer == LatentOptimizer::Adam) return adam(energy, x0, settings, ctx, iteration_offset, total, stats);
  return lbfgs([&energy](const double* x, double* gradient) { return energy.evaluate(x, gradient); }, x0, settings,
               ctx, iteration_offset, total, stats);
}

}  // namespace mf
