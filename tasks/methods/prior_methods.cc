#include <algorithm>
#include <cmath>
#include <vector>

#include "prior/runtime/nemf_runtime.h"
#include "prior/motion/errors.h"
#include "tasks/constraints/interpolation_fill.h"
#include "tasks/context/model_rig.h"
#include "tasks/latent/latent_solver.h"
#include "tasks/latent/prior_codec.h"
#include "tasks/methods/method.h"

namespace mf {

namespace {

// Upsampling by a whole factor r = model fps / input fps (15 -> 30 with a
// 30 fps model): the input frames are every r-th frame of a motion at the
// model's rate, so the frames between them are an in-betweening problem with
// dense keys. The answer is a blend of local quintic interpolation through the
// input frames (resample_quintic) and the latent solver's solution started
// from it, with the prior's weight growing with the distance between input
// frames: clamp((log2 r - 1) / 2, 0, 1), i.e. 0 at r = 2 (the quintic alone,
// no solve), 0.5 at r = 4, 1 at r = 8 and beyond. Chosen on the training split
// (docs/BENCHMARKS.md, "Resampling"), L2P at prior weights 0 / 0.25 / 0.5 /
// 0.75 / 1: at r = 2 the interpolation's error is below the prior's
// reconstruction error (0.062 at 0, 0.062 at 0.15, 0.067 at 0.3); r = 4: 0.274
// / 0.231 / 0.206 / 0.204 / 0.228; r = 8: 1.381 / 1.100 / 0.832 / 0.595 /
// 0.476. The dense result goes to the output rate by the quintic (at the
// model's rate the input is dense; see kCodecFromRatio). Returns false when the
// rates are not in such a ratio.
bool upsample_by_solving(const Motion& in, double fps, int frames, const TaskContext& ctx, Motion* out,
                         std::vector<std::string>* warnings) {
  const double model_fps = ctx.model->config().fps;
  const double ratio = model_fps / in.fps;
  const long r = std::lround(ratio);
  if (r < 2 || std::abs(ratio - static_cast<double>(r)) > 1e-5 * ratio || in.num_frames() < 2) return false;
  const double frames_at_rate = static_cast<double>(in.num_frames() - 1) * static_cast<double>(r) + 1.0;
  if (frames_at_rate > kMaxResampledFrames)
    throw InputError("the motion would span more than " + std::to_string(static_cast<long>(kMaxResampledFrames)) +
                     " frames at the model's frame rate");
  const int n = static_cast<int>(frames_at_rate);
  const Motion quintic = resample_quintic(in, model_fps, n);
  const double prior_weight = std::clamp((std::log2(static_cast<double>(r)) - 1.0) / 2.0, 0.0, 1.0);
  Motion dense = quintic;
  if (prior_weight > 0.0) {
    std::vector<int> known;
    for (int i = 0; i < n; i += static_cast<int>(r)) known.push_back(i);
    // 20 iterations: the setting the weights above were chosen with.
    LatentSolverOptions solver = default_solver_options(LatentOptimizer::Lbfgs);
    solver.max_iterations = ctx.max_iterations > 0 ? ctx.max_iterations : 20;
    // Where the prior cannot fit the input frames (real capture unlike its
    // training data: the foreign training split at r = 4 and 8 lost 0.05 and
    // 0.10 of interpolation's L2P to the quintic without this), keep the quintic.
    solver.fallback.enabled = ctx.interpolation_fallback;
    solver.fallback.toward_input = true;
    CompletionReport report;
    const Motion solved =
        complete_motion(*ctx.model, quintic, MotionConstraints::full_pose(known), solver, ctx, &report);
    warnings->insert(warnings->end(), report.warnings.begin(), report.warnings.end());
    // Key frames are equal in both, so they stay exact.
    for (int f = 0; f < n; ++f) {
      for (int j = 0; j < dense.num_joints(); ++j)
        dense.rotation(f, j) = quintic.rotation(f, j).slerp(prior_weight, solved.rotation(f, j));
      dense.root_positions[f] = quintic.root_positions[f] * (1 - prior_weight) + solved.root_positions[f] * prior_weight;
    }
  }
  *out = resample_quintic(dense, fps, frames);  // at the model's rate: copies the dense frames, holds past the end
  return true;
}

// Input rates in any other ratio to the model's (24 -> 30, 30 -> 60, 30 ->
// 24, 12 -> 30, ...) have no model frames to solve at. Measured at whole ratios
// r = model fps / input fps with the path forced (training split, 100 windows,
// L2P; docs/BENCHMARKS.md, "Resampling with the prior"), the
// encode / decode with the residual loses to the Catmull-Rom spline up to r = 6
// (r = 2: 0.193 against 0.071; 4: 0.502 against 0.335; 6: 0.899 against 0.813),
// ties at 7 (0.987 / 0.976) and wins at 8 (1.226 / 1.348); the quintic is at or
// below the spline up to 6 (0.761 at 6) and level with it at 8 (1.381). So the
// quintic serves inputs up to 7 times sparser than the model's rate, the codec
// sparser ones.
constexpr double kCodecFromRatio = 7.0;

}  // namespace

std::vector<Method> prior_methods() {
  // Resampling with the prior: when the model's rate is a whole multiple of the
  // input's, the frames in between come from the quintic and the latent solver
  // (above); other ratios take the quintic, or for very sparse input
  // (kCodecFromRatio) encode, decode at the new times and add the input's
  // residual so the input frames come out exactly. The codec's variants were
  // chosen by measurement (docs/BENCHMARKS.md, "Resampling with the prior"):
  // the residual is essential; the root path from the input (LERP plus the
  // zero residual) scored as well as the global motion predictor's and skips it.
  Method prior;
  prior.name = "prior";
  prior.description =
      "the prior at the new times: when the model's rate is a multiple of the input's, local quintic interpolation "
      "through the input frames blended with a latent solve through them (the solve's weight growing with the "
      "ratio); other ratios: the quintic, or for input 7+ times sparser than the model's rate encode/decode "
      "corrected to pass through every input frame (resampling)";
  prior.needs_model = true;
  prior.resample = [](const Motion& in, double fps, int frames, const TaskContext& ctx,
                      std::vector<std::string>* warnings) {
    require_prior(ctx, "method 'prior'");
    Motion out;
    if (upsample_by_solving(in, fps, frames, ctx, &out, warnings)) return out;
    if (in.num_frames() < 2 || ctx.model->config().fps / in.fps < kCodecFromRatio) return resample_quintic(in, fps, frames);
    PriorResampleOptions options;
    options.residual = true;
    options.root = RootSource::kInput;
    return resample_with_prior(in, fps, frames, ctx, options);
  };
  // complete: the latent solvers (tasks/methods/solver_methods.cc) do in-betweening.
  return {prior};
}

}  // namespace mf
