// The latent solvers as task methods: "nemf" (L-BFGS, tasks/latent_solver.h)
// and "nemf-adam" (NeMF's Adam-600 reference).
#include "prior/motion/errors.h"
#include "tasks/latent_solver.h"
#include "tasks/method.h"

namespace mf {

namespace {

Method solver_method(const char* name, const char* description, SolverMethod method) {
  Method m;
  m.name = name;
  m.description = description;
  m.needs_model = true;
  m.complete = [method](const Motion& input, const std::vector<int>& known, const TaskContext& ctx) {
    if (!ctx.model) throw InputError("this method needs the prior, and no model is loaded");
    return complete_motion(*ctx.model, input, MotionConstraints::full_pose(known), default_solver_options(method), ctx);
  };
  return m;
}

}  // namespace

std::vector<Method> solver_methods() {
  return {solver_method("nemf", "latent optimisation of the prior with L-BFGS (Ceres), NeMF's energies",
                        SolverMethod::Lbfgs),
          solver_method("nemf-adam", "latent optimisation of the prior with Adam, 600 iterations (NeMF's reference)",
                        SolverMethod::Adam)};
}

}  // namespace mf
