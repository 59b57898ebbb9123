#include "tasks/method.h"
#include "tasks/prior_codec.h"

namespace mf {

std::vector<Method> prior_methods() {
  // Resampling with the prior: encode, decode at the new times, add the input's
  // residual so the input frames come out exactly. The variant was chosen by
  // measurement (docs/BENCHMARKS.md, "Resampling with the prior"): the residual
  // is essential; the root path from the input (LERP plus the zero residual)
  // scored as well as the global motion predictor's and skips it.
  Method prior;
  prior.name = "prior";
  prior.description = "the prior's decode at the new times, corrected to pass through every input frame (resampling)";
  prior.needs_model = true;
  prior.resample = [](const Motion& in, double fps, int frames, const TaskContext& ctx) {
    PriorResampleOptions options;
    options.residual = true;
    options.root = RootSource::kInput;
    return resample_with_prior(in, fps, frames, ctx, options);
  };
  // complete: the latent solvers (tasks/solver_methods.cc) do in-betweening.
  return {prior};
}

}  // namespace mf
