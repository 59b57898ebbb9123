// The optimiser shared by every latent-space task (tasks/latent_solver.h,
// tasks/renav.h): minimises a differentiable energy of a flat latent vector
// x = [z_l, z_g] with L-BFGS (Ceres GradientProblemSolver, gradients from
// torch autograd) or with Adam (NeMF's reference), reporting progress through
// the task context once per iteration so that callers can observe and cancel.
#pragma once

#include <ATen/core/Tensor.h>
#include <functional>
#include <string>
#include <vector>

#include "tasks/task_context.h"

namespace mf {

/// The energy of x ([n] float): a differentiable scalar tensor.
using LatentEnergy = std::function<at::Tensor(const at::Tensor& x)>;

enum class LatentOptimizer { Lbfgs, Adam };

struct LatentOptimizerSettings {
  LatentOptimizer method = LatentOptimizer::Lbfgs;
  int max_iterations = 20;
  // L-BFGS (Ceres semantics).
  int lbfgs_rank = 20;
  bool lbfgs_eigenvalue_scaling = false;
  double function_tolerance = 1e-3;
  double gradient_tolerance = 1e-8;
  double parameter_tolerance = 1e-7;
  // Adam: learning rate times `adam_decay` every `adam_decay_every` iterations;
  // stops when the best energy improved by less than `adam_tolerance`
  // (relative) over `adam_patience` iterations. The best x seen is returned.
  double adam_lr = 0.1;
  int adam_decay_every = 200;
  double adam_decay = 0.7;
  double adam_tolerance = 1e-4;
  int adam_patience = 100;
};

struct LatentOptimizerStats {
  int iterations = 0;
  int evaluations = 0;       ///< energy evaluations (with or without gradient)
  bool converged = false;    ///< stopped by a tolerance, not by the iteration cap
  std::string message;       ///< the stop reason
};

/// Minimises `energy` from x0 ([n] float); returns the solution ([n] float).
/// Progress reports carry iteration = `iteration_offset` + this run's
/// iteration and max_iterations = `iteration_total` (0: this run's cap).
/// Throws CancelledError when the context asks to stop, mf::InputError for
/// invalid settings, and rethrows any exception raised by the energy.
at::Tensor minimize_latent(const LatentEnergy& energy, const at::Tensor& x0, const LatentOptimizerSettings& settings,
                           const TaskContext& ctx, LatentOptimizerStats* stats, int iteration_offset = 0,
                           int iteration_total = 0);

}  // namespace mf
