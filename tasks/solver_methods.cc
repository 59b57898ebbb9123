// The latent solvers as task methods: "nemf" (L-BFGS, tasks/latent_solver.h),
// "nemf-adam" (NeMF's Adam-600 reference), and L-BFGS started from a
// transformer in-betweener (tasks/initializers.h TransformerEncoderInitializer):
// "nemf-context", "nemf-detail" (two-stage model) and "nemf-citl".
#include "prior/model/nemf.h"
#include "tasks/inbetweener_files.h"
#include "tasks/latent_solver.h"
#include "tasks/method.h"

namespace mf {

namespace {

// `initializer` empty: the default (interpolation); else a make_initializer()
// name whose transformer (`inbetweener` kind) comes from the context.
Method solver_method(const char* name, const char* description, SolverMethod method,
                     const std::string& initializer = "", const std::string& inbetweener = "") {
  Method m;
  m.name = name;
  m.description = description;
  m.needs_model = true;
  m.needs_inbetweener = inbetweener;
  LatentSolverOptions options = default_solver_options(method);
  if (!initializer.empty()) options.initializer = make_initializer(initializer);
  const std::string method_name = name;
  m.complete = [options, method_name, inbetweener](const Motion& input, const std::vector<int>& known,
                                                   const TaskContext& ctx) {
    const NemfModel& model = require_prior(ctx, "method '" + method_name + "'");
    if (!inbetweener.empty()) require_inbetweener(ctx, inbetweener, "method '" + method_name + "'");
    return complete_motion(model, input, MotionConstraints::full_pose(known), options, ctx);
  };
  return m;
}

}  // namespace

std::vector<Method> solver_methods() {
  return {solver_method("nemf", "latent optimisation of the prior with L-BFGS (Ceres), NeMF's energies",
                        SolverMethod::Lbfgs),
          solver_method("nemf-adam", "latent optimisation of the prior with Adam, 600 iterations (NeMF's reference)",
                        SolverMethod::Adam),
          solver_method("nemf-context", "L-BFGS latent optimisation started from the Context Transformer",
                        SolverMethod::Lbfgs, "context-encoder", "twostage"),
          solver_method("nemf-detail", "L-BFGS latent optimisation started from the two-stage transformer",
                        SolverMethod::Lbfgs, "detail-encoder", "twostage"),
          solver_method("nemf-citl", "L-BFGS latent optimisation started from the CITL transformer",
                        SolverMethod::Lbfgs, "citl-encoder", "citl")};
}

}  // namespace mf
