#include <algorithm>
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
// dense keys. The answer is a blend of a Catmull-Rom spline through the input
// frames (resample_cubic) and the latent solver's solution started from that
// spline, with the prior's weight growing with the distance between input
// frames: clamp((log2 r - 1) / 2, 0, 1), i.e. 0 at r = 2 (the spline alone,
// no solve), 0.5 at r = 4, 1 at r = 8 and beyond. Chosen on the training split
// (docs/BENCHMARKS.md, "Session 12: resampling"): at r = 2 the spline's error
// is below the prior's reconstruction error and every prior weight loses (L2P
// 0.071 / 0.077 / 0.097 at 0 / 0.25 / 0.5); at r = 4 the blend wins (0.335 /
// 0.267 / 0.292 at 0 / 0.5 / 1); at r = 8 the solution alone does (1.348 /
// 0.875 / 0.596). Returns false when the rates are not in such a ratio.
bool upsample_by_solving(const Motion& in, double fps, int frames, const TaskContext& ctx,
                         const PriorResampleOptions& options, Motion* out) {
  const double model_fps = ctx.model->config().fps;
  const double ratio = model_fps / in.fps;
  const long r = std::lround(ratio);
  if (r < 2 || std::abs(ratio - static_cast<double>(r)) > 1e-5 * ratio || in.num_frames() < 2) return false;
  const int n = (in.num_frames() - 1) * static_cast<int>(r) + 1;
  const Motion spline = resample_cubic(in, model_fps, n);
  const double prior_weight = std::clamp((std::log2(static_cast<double>(r)) - 1.0) / 2.0, 0.0, 1.0);
  Motion dense = spline;
  if (prior_weight > 0.0) {
    std::vector<int> known;
    for (int i = 0; i < n; i += static_cast<int>(r)) known.push_back(i);
    // 20 iterations: the setting the weights above were chosen with.
    LatentSolverOptions solver = default_solver_options(SolverMethod::Lbfgs);
    solver.max_iterations = ctx.max_iterations > 0 ? ctx.max_iterations : 20;
    const Motion solved = complete_motion(*ctx.model, spline, MotionConstraints::full_pose(known), solver, ctx);
    // Key frames are equal in both, so they stay exact.
    for (int f = 0; f < n; ++f) {
      for (int j = 0; j < dense.num_joints(); ++j)
        dense.rotation(f, j) = spline.rotation(f, j).slerp(prior_weight, solved.rotation(f, j));
      dense.root_positions[f] = spline.root_positions[f] * (1 - prior_weight) + solved.root_positions[f] * prior_weight;
    }
  }
  if (same_frame_rate(fps, model_fps)) {
    *out = resample_interpolate(dense, fps, frames);  // copies the dense frames, holds past the end
  } else {
    *out = resample_with_prior(dense, fps, frames, ctx, options);
  }
  return true;
}

}  // namespace

std::vector<Method> prior_methods() {
  // Resampling with the prior: encode, decode at the new times, add the input's
  // residual so the input frames come out exactly; when the model's rate is a
  // whole multiple of the input's, the frames in between come from a spline
  // and the latent solver (above). The variants were chosen by measurement
  // (docs/BENCHMARKS.md, "Resampling with the prior"): the residual is
  // essential; the root path from the input (LERP plus the zero residual)
  // scored as well as the global motion predictor's and skips it.
  Method prior;
  prior.name = "prior";
  prior.description =
      "the prior at the new times: when the model's rate is a multiple of the input's, a Catmull-Rom spline through "
      "the input frames blended with a latent solve through them (the solve's weight growing with the ratio), else "
      "encode/decode corrected to pass through every input frame (resampling)";
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
