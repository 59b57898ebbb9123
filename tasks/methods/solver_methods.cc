// The latent solvers as task methods: "nemf" (L-BFGS, tasks/latent/latent_solver.h),
// "nemf-adam" (NeMF's Adam-600 reference), and L-BFGS started from a
// transformer in-betweener (tasks/latent/initializers.h TransformerEncoderInitializer):
// "nemf-context", "nemf-detail" (two-stage model) and "nemf-citl".
#include "prior/inbetween/inbetweener_kinds.h"
#include "tasks/latent/latent_solver.h"
#include "tasks/methods/method.h"
#include "tasks/transformer/inbetweener_files.h"

namespace mf {

namespace {

// The noise on the starting codes of an alternative solution
// (LatentSolverOptions::start_noise), measured in docs/BENCHMARKS.md
// ("Alternatives").
constexpr double kAlternativeStartNoise = 0.5;

// `initializer` empty: the default (interpolation); else a make_initializer()
// name whose transformer (`inbetweener` kind) comes from the context.
Method solver_method(const std::string& name, const std::string& description, LatentOptimizer optimizer,
                     const std::string& initializer = "", const std::string& inbetweener = "") {
  Method m;
  m.name = name;
  m.description = description;
  m.needs_model = true;
  m.needs_inbetweener = inbetweener;
  m.follows_trajectory = true;  // the trajectory energy (tasks/latent/runtime_energy.h)
  LatentSolverOptions options = default_solver_options(optimizer);
  if (!initializer.empty()) options.initializer = make_initializer(initializer);
  m.complete = [options, method_name = name, inbetweener](const Motion& input, const std::vector<int>& known,
                                                   const TaskContext& ctx, CompletionNotes* notes) {
    const runtime::NemfRuntime& model = require_prior(ctx, "method '" + method_name + "'");
    if (!inbetweener.empty()) require_inbetweener(ctx, inbetweener, "method '" + method_name + "'");
    LatentSolverOptions o = options;
    if (ctx.max_iterations > 0) o.max_iterations = ctx.max_iterations;
    // Whole-pose keys: where the prior cannot reach them, interpolation (tasks/latent/fallback.h).
    o.fallback.enabled = o.optimizer == LatentOptimizer::Lbfgs && ctx.interpolation_fallback;
    CompletionReport report;
    Motion out = complete_motion(model, input, MotionConstraints::full_pose(known), o, ctx, &report);
    if (notes) {
      notes->interpolated = !report.trust.empty();
      for (const WindowTrust& t : report.trust) notes->interpolated = notes->interpolated && t.interpolated;
      for (std::string& w : report.warnings) notes->warnings.push_back(std::move(w));
    }
    return out;
  };
  m.complete_constrained = [options, method_name = name, inbetweener](const Motion& input, const MotionConstraints& c,
                                                               int variant, const TaskContext& ctx,
                                                               std::vector<std::string>* warnings) {
    const runtime::NemfRuntime& model = require_prior(ctx, "method '" + method_name + "'");
    if (!inbetweener.empty()) require_inbetweener(ctx, inbetweener, "method '" + method_name + "'");
    LatentSolverOptions o = options;
    if (ctx.max_iterations > 0) o.max_iterations = ctx.max_iterations;
    if (variant > 0) {
      o.start_noise = kAlternativeStartNoise;
      o.start_seed = ctx.seed * 7919u + static_cast<uint64_t>(variant);
    }
    CompletionReport report;
    Motion out = complete_motion(model, input, c, o, ctx, &report);
    for (std::string& w : report.warnings) warnings->push_back(std::move(w));
    return out;
  };
  return m;
}

}  // namespace

std::vector<Method> solver_methods() {
  std::vector<Method> methods = {
      solver_method("nemf", "latent optimisation of the prior with L-BFGS (Ceres), NeMF's energies",
                    LatentOptimizer::Lbfgs),
      solver_method("nemf-adam", "latent optimisation of the prior with Adam, 600 iterations (NeMF's reference)",
                    LatentOptimizer::Adam)};
  // One per stage of every in-betweener kind: "nemf-context", "nemf-detail", "nemf-citl".
  for (const InbetweenerKind& kind : inbetweener_kinds()) {
    for (const InbetweenerStage& stage : kind.stages) {
      methods.push_back(solver_method("nemf-" + stage.name,
                                      "L-BFGS latent optimisation started from the " + kind.title + " (" +
                                          stage.description + ")",
                                      LatentOptimizer::Lbfgs, stage.name + "-encoder", kind.name));
    }
  }
  return methods;
}

}  // namespace mf
