// The optimiser shared by every latent-space task (tasks/latent/latent_solver.h,
// tasks/renav/renav.h): minimises an energy of a flat latent vector
// x = [z_l, z_g] that evaluates itself and its gradient (DirectLatentEnergy:
// the Eigen runtime's energies, or a libtorch energy through
// TensorLatentEnergy of tasks/reference/latent_energy.h) with L-BFGS (Ceres
// GradientProblemSolver) or with Adam (NeMF's reference), reporting progress
// through the task context once per iteration so that callers can observe
// and cancel. No libtorch here.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "tasks/context/task_context.h"

namespace mf {

/// The optimiser: L-BFGS (Ceres) or Adam (NeMF's reference). The methods
/// "nemf" and "nemf-adam" of every latent-space task choose it.
enum class LatentOptimizer { Lbfgs, Adam };

/// The optimiser and the settings of both. The options of every latent-space task
/// embed them (LatentSolverOptions, RenavOptions derive from this struct) and
/// set their own defaults; the values here are the latent solvers'
/// (tasks/latent/latent_solver.h).
struct LatentOptimizerSettings {
  LatentOptimizer optimizer = LatentOptimizer::Lbfgs;
  /// Iteration cap. minimize_latent() runs at most this many iterations; in a
  /// task's options 0 means the task's default cap.
  int max_iterations = 0;
  // L-BFGS (Ceres GradientProblemSolver semantics).
  int lbfgs_rank = 20;               ///< memory of the Hessian approximation
  /// Ceres' use_approximate_eigenvalue_bfgs_scaling: scales the initial
  /// inverse Hessian (helps when the energy's scale is far from 1).
  bool lbfgs_eigenvalue_scaling = false;
  double function_tolerance = 1e-3;  ///< stop when |delta f| / f falls below this
  double gradient_tolerance = 1e-8;  ///< ... or max |gradient| relative to the initial one below this
  double parameter_tolerance = 1e-6; ///< ... or the step relative to |x| below this
  // Adam (NeMF's reference): learning rate times `adam_decay` every
  // `adam_decay_every` iterations; stops when the best energy improved by
  // less than `adam_tolerance` (relative) over `adam_patience` iterations.
  // The best x seen is returned.
  double adam_lr = 0.1;
  int adam_decay_every = 200;
  double adam_decay = 0.7;
  double adam_tolerance = 1e-4;
  int adam_patience = 100;

  /// Empty when valid, else what is wrong, each problem followed by "; ".
  std::string validate() const;
  /// These settings alone (without a task's other options), with the cap
  /// `max_iterations`.
  LatentOptimizerSettings capped(int max_iterations) const {
    LatentOptimizerSettings s = *this;
    s.max_iterations = max_iterations;
    return s;
  }
};

struct LatentOptimizerStats {
  int iterations = 0;
  int evaluations = 0;       ///< energy evaluations (with or without gradient)
  bool converged = false;    ///< stopped by a tolerance, not by the iteration cap
  std::string message;       ///< the stop reason
};

/// An energy of x ([size()] values) that evaluates itself and its gradient:
/// the Eigen runtime's (RuntimeLatentEnergy, tasks/latent/runtime_latent_energy.h)
/// or a libtorch energy's adapter (FlatLatentEnergy, tasks/reference/). It keeps buffers
/// between evaluations, so evaluating is not const; one per thread.
class DirectLatentEnergy {
 public:
  virtual ~DirectLatentEnergy() = default;
  virtual int size() const = 0;
  /// The total at x and, when `gradient` is not null, its gradient there.
  virtual double evaluate(const double* x, double* gradient) = 0;
  /// Each active term's weighted value (named and ordered as EnergyTerms,
  /// tasks/reference/latent_energy.h) and, in *total, their sum at x.
  virtual std::vector<std::pair<std::string, double>> terms(const double* x, double* total) = 0;
};

/// Minimises `energy` from x0 ([energy.size()] values) with
/// settings.optimizer, at most settings.max_iterations iterations; returns the
/// solution. Progress reports carry iteration = `iteration_offset` + this
/// run's iteration and max_iterations = `iteration_total` (0: this run's cap).
/// Adam runs in double on the energy's gradients (torch.optim.Adam's update,
/// beta 0.9 / 0.999, eps 1e-8) and returns the best x it evaluated.
/// Throws CancelledError when the context asks to stop, mf::InputError for
/// invalid settings or a start of the wrong size, and rethrows any exception
/// raised by the energy.
Eigen::VectorXd minimize_latent(DirectLatentEnergy& energy, const Eigen::VectorXd& x0,
                                const LatentOptimizerSettings& settings, const TaskContext& ctx,
                                LatentOptimizerStats* stats, int iteration_offset = 0, int iteration_total = 0);

}  // namespace mf
