#include "tasks/model_rig.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <optional>

#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "prior/util/binary_io.h"
#include "tasks/baselines.h"
#include "tasks/residuals.h"

namespace mf {
namespace {

// Model-rate frames of a motion at `fps` with `frames` frames: enough to cover
// its time span (the last model frame may reach past the end; it is clamped).
int model_rate_frames(int frames, double fps, double model_fps) {
  const double exact = (frames - 1) * model_fps / fps;
  const double r = std::round(exact);
  return static_cast<int>(std::abs(exact - r) <= 1e-5 * std::max(1.0, r) ? r : std::ceil(exact)) + 1;
}

// Known frames at the model's rate: model frames whose time lies within a run
// of consecutive known input frames take the resampled pose; a run too short
// to contain one gives its nearest model frame the run's first pose exactly.
std::vector<int> model_rate_known(const std::vector<int>& known, double fps, double model_fps, int model_frames,
                                  const Motion& input_rate, Motion* model_rate) {
  std::vector<int> out;
  for (size_t i = 0; i < known.size();) {
    size_t k = i;
    while (k + 1 < known.size() && known[k + 1] == known[k] + 1) ++k;
    const double t0 = known[i] / fps, t1 = known[k] / fps, eps = 1e-6;
    const int first = static_cast<int>(std::ceil(t0 * model_fps - eps)), last = static_cast<int>(std::floor(t1 * model_fps + eps));
    if (first <= last) {
      for (int m = std::max(0, first); m <= std::min(last, model_frames - 1); ++m) out.push_back(m);
    } else {
      const int m = std::clamp(static_cast<int>(std::lround(t0 * model_fps)), 0, model_frames - 1);
      for (int j = 0; j < model_rate->num_joints(); ++j) model_rate->rotation(m, j) = input_rate.rotation(known[i], j);
      model_rate->root_positions[m] = input_rate.root_positions[known[i]];
      out.push_back(m);
    }
    i = k + 1;
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  if (out.size() < 2)
    throw InputError("the known frames are too close together in time to solve at the model's " +
                     std::to_string(static_cast<int>(model_fps)) + " fps");
  return out;
}

}  // namespace

std::shared_ptr<const RigAnatomy> load_rig_anatomy_next_to(const std::string& prior_file, const Skeleton& model) {
  const std::filesystem::path path = std::filesystem::path(prior_file).parent_path() / kRigAnatomyFileName;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return nullptr;
  const std::string text = read_file_limited(path.string(), "rig anatomy file", kMaxTextFileBytes);
  return std::make_shared<const RigAnatomy>(RigAnatomy::from_json(text, model, path.string()));
}

bool needs_model_rig(const Motion& input, const TaskContext& ctx) {
  if (!ctx.model) return false;
  return !input.skeleton.same_as(ctx.model->rig().skeleton) || !same_frame_rate(input.fps, ctx.model->config().fps);
}

RigMap model_rig_map(const Skeleton& user, const TaskContext& ctx) {
  const Skeleton& model = require_prior(ctx, "this method").rig().skeleton;
  try {
    return map_rig(user, model, ctx.rig_map);
  } catch (const InputError& e) {
    if (ctx.rig_map_source.empty()) throw;
    throw InputError(ctx.rig_map_source + ": " + e.what());
  }
}

void check_model_rig(const Skeleton& input, const TaskContext& ctx) {
  if (!ctx.model || input.same_as(ctx.model->rig().skeleton)) return;
  if (!ctx.model_anatomy) {
    const std::string what = "the motion has " + std::to_string(input.num_joints()) +
                             " joints on another rig than the model's (" +
                             std::to_string(ctx.model->rig().num_joints()) + " joints), and ";
    if (!ctx.model_anatomy_error.empty())
      throw ModelMissingError(what + "the model's rig anatomy file did not load: " + ctx.model_anatomy_error);
    throw InputError(what + "the model has no rig anatomy to retarget with (" + kRigAnatomyFileName +
                     " next to the model file)");
  }
  model_rig_map(input, ctx);
}

Retargeter model_retargeter(const Motion& input, const std::vector<int>& known, const TaskContext& ctx) {
  const Skeleton& model = require_prior(ctx, "this method").rig().skeleton;
  check_model_rig(input.skeleton, ctx);
  RigMap map = model_rig_map(input.skeleton, ctx);
  RigAnatomy user = estimate_anatomy(input, map.user_parts, known);
  return Retargeter(input.skeleton, model, std::move(map), std::move(user), *ctx.model_anatomy);
}

Motion match_known_frames(const Motion& out_in, const Motion& input, const std::vector<int>& known) {
  Motion out = out_in;
  for (int j = 0; j < out.num_joints(); ++j)
    spread_rotation_residual(input, out_in, j, known, ResidualRamp::Linear, &out);
  spread_root_residual(input, out_in, known, ResidualRamp::Linear, &out);
  return out;
}

Motion complete_on_model_rig(const Motion& input, const std::vector<int>& known, const TaskContext& ctx,
                             const CompleteFn& complete) {
  if (!needs_model_rig(input, ctx)) return complete(input, known);
  const NemfModel& prior = require_prior(ctx, "this method");
  const double model_fps = prior.config().fps;
  const bool native = input.skeleton.same_as(prior.rig().skeleton);
  // The reference: interpolation between the known frames on the user's rig
  // (what joints the model lacks follow; reads only known frames).
  const Motion reference = interpolate_motion(input, known);
  std::optional<Retargeter> rig;
  if (!native) rig.emplace(model_retargeter(input, known, ctx));
  const Motion on_model = native ? reference : rig->to_model(reference);

  Motion result;
  if (same_frame_rate(input.fps, model_fps)) {
    result = complete(on_model, known);
  } else {
    const int frames = model_rate_frames(input.num_frames(), input.fps, model_fps);
    Motion at_rate = resample_interpolate(on_model, model_fps, frames);
    const std::vector<int> rate_known =
        model_rate_known(known, input.fps, model_fps, frames, on_model, &at_rate);
    const Motion solved = complete(at_rate, rate_known);
    result = resample_interpolate(solved, input.fps, input.num_frames());
  }
  Motion back = native ? result : rig->to_user(result, reference);
  back.skeleton = input.skeleton;
  back.fps = input.fps;
  return match_known_frames(back, input, known);
}

Motion resample_on_model_rig(const Motion& input, double fps, int frames, const TaskContext& ctx,
                             const ResampleFn& resample) {
  if (!ctx.model || input.skeleton.same_as(ctx.model->rig().skeleton)) return resample(input, fps, frames);
  const Retargeter rig = model_retargeter(input, {}, ctx);
  const Motion result = resample(rig.to_model(input), fps, frames);
  Motion back = rig.to_user(result, resample_interpolate(input, fps, frames));
  back.skeleton = input.skeleton;
  return back;
}

}  // namespace mf
