#include <cmath>
#include <vector>

#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "tasks/baselines.h"
#include "tasks/latent_solver.h"
#include "tasks/method.h"
#include "tasks/prior_codec.h"

namespace mf {

namespace {

// Upsampling by a whole factor r = model fps / input fps (15 -> 30 with a
// 30 fps model): the input frames are every r-th frame of a motion at the
// model's rate, so the frames between them are an in-betweening problem with
// dense keys, which the latent solver answers better than encoding the
// interpolated motion (docs/BENCHMARKS.md, "Resampling with the prior").
// Returns false when the rates are not in such a ratio.
bool upsample_by_solving(const Motion& in, double fps, int frames, const TaskContext& ctx,
                         const PriorResampleOptions& options, Motion* out) {
  const double model_fps = ctx.model->config().fps;
  const double ratio = model_fps / in.fps;
  const long r = std::lround(ratio);
  if (r < 2 || std::abs(ratio - static_cast<double>(r)) > 1e-5 * ratio || in.num_frames() < 2) return false;
  const int n = (in.num_frames() - 1) * static_cast<int>(r) + 1;
  const Motion dense = resample_interpolate(in, model_fps, n);
  std::vector<int> known;
  for (int i = 0; i < n; i += static_cast<int>(r)) known.push_back(i);
  // 20 iterations: the setting the blend below was chosen and measured with
  // (the solver's default rose to 40 later, not re-measured for resampling).
  LatentSolverOptions solver = default_solver_options(SolverMethod::Lbfgs);
  solver.max_iterations = ctx.max_iterations > 0 ? ctx.max_iterations : 20;
  const Motion solved_raw = complete_motion(*ctx.model, dense, MotionConstraints::full_pose(known), solver, ctx);
  // Half-way between the interpolation and the solution (SLERP / LERP): the
  // solution's frames between keys carry the prior's reconstruction error
  // (about 4 degrees), which on its own loses to interpolation on L2Q; the
  // blend beats both. Weight chosen on the training split (0.35 / 0.5 / 0.65:
  // L2P 0.138 / 0.134 / 0.134, L2Q 0.035 / 0.036 / 0.036, NPSS 0.0079 / 0.0070 /
  // 0.0062; interpolation 0.165 / 0.037 / 0.0103; the solution alone 0.150 /
  // 0.039 / 0.0053). Key frames are equal in both, so they stay exact.
  constexpr double kPriorWeight = 0.5;
  Motion solved = solved_raw;
  for (int f = 0; f < n; ++f) {
    for (int j = 0; j < solved.num_joints(); ++j)
      solved.rotation(f, j) = dense.rotation(f, j).slerp(kPriorWeight, solved_raw.rotation(f, j));
    solved.root_positions[f] = dense.root_positions[f] * (1 - kPriorWeight) + solved_raw.root_positions[f] * kPriorWeight;
  }
  if (same_frame_rate(fps, model_fps)) {
    *out = resample_interpolate(solved, fps, frames);  // copies the solved frames, holds past the end
  } else {
    *out = resample_with_prior(solved, fps, frames, ctx, options);
  }
  return true;
}

}  // namespace

std::vector<Method> prior_methods() {
  // Resampling with the prior: encode, decode at the new times, add the input's
  // residual so the input frames come out exactly; when the model's rate is a
  // whole multiple of the input's, the frames in between are first solved for
  // with the latent solver (above). The variants were chosen by measurement
  // (docs/BENCHMARKS.md, "Resampling with the prior"): the residual is
  // essential; the root path from the input (LERP plus the zero residual)
  // scored as well as the global motion predictor's and skips it.
  Method prior;
  prior.name = "prior";
  prior.description =
      "the prior at the new times: latent solve through the input frames when the model's rate is a multiple of "
      "the input's, else encode/decode corrected to pass through every input frame (resampling)";
  prior.needs_model = true;
  prior.resample = [](const Motion& in, double fps, int frames, const TaskContext& ctx) {
    require_prior(ctx, "method 'prior'");
    PriorResampleOptions options;
    options.residual = true;
    options.root = RootSource::kInput;
    Motion out;
    if (upsample_by_solving(in, fps, frames, ctx, options, &out)) return out;
    return resample_with_prior(in, fps, frames, ctx, options);
  };
  // complete: the latent solvers (tasks/solver_methods.cc) do in-betweening.
  return {prior};
}

}  // namespace mf
