#include "tasks/context/model_rig.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <optional>

#include "prior/runtime/nemf_runtime.h"
#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "prior/util/binary_io.h"
#include "tasks/constraints/interpolation_fill.h"
#include "tasks/constraints/residuals.h"
#include "tasks/context/ground_level.h"
#include "tasks/fixups/effector_ik.h"
#include "tasks/fixups/foot_locking.h"

namespace mf {
namespace {

// Model-rate frames of a motion at `fps` with `frames` frames: enough to cover
// its time span (the last model frame may reach past the end; it is clamped).
int model_rate_frames(int frames, double fps, double model_fps) {
  const double exact = (frames - 1) * model_fps / fps;
  const double r = std::round(exact);
  const double count = (std::abs(exact - r) <= 1e-5 * std::max(1.0, r) ? r : std::ceil(exact)) + 1;
  // Not `count > max`: an overflowing ratio gives inf or NaN, which must not reach the cast.
  if (!(count <= kMaxResampledFrames)) {
    std::ostringstream msg;
    msg << frames << " frames at " << fps << " fps span more than " << static_cast<long long>(kMaxResampledFrames)
        << " frames at the model's " << model_fps << " fps";
    throw InputError(msg.str());
  }
  return static_cast<int>(count);
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

// How the constraints of a motion on the user's rig and rate read on the
// model's: frames rescaled in time, joints through the rig map, positions scaled.
struct ConstraintMapping {
  double frame_scale = 1.0;  ///< model frames per user frame
  int model_frames = 0;
  double position_scale = 1.0;
  const Skeleton* user = nullptr;
  const RigMap* map = nullptr;  ///< null: the same skeleton

  int frame(int f) const { return clamped(std::lround(f * frame_scale)); }
  // A pin covers at least the time of the user's: its ends rounded outwards.
  int first_frame(int f) const { return clamped(static_cast<long>(std::floor(f * frame_scale + 1e-6))); }
  int last_frame(int f) const { return clamped(static_cast<long>(std::ceil(f * frame_scale - 1e-6))); }
  int clamped(long f) const { return static_cast<int>(std::clamp<long>(f, 0, model_frames - 1)); }
  std::vector<int> joints(const std::vector<int>& user_joints) const {
    if (!map) return user_joints;
    std::vector<int> out;
    for (size_t m = 0; m < map->user_of_model.size(); ++m) {
      const int u = map->user_of_model[m];
      if (u >= 0 && std::find(user_joints.begin(), user_joints.end(), u) != user_joints.end())
        out.push_back(static_cast<int>(m));
    }
    return out;
  }
  int joint(int u, const std::string& what) const {
    if (!map) return u;
    for (size_t m = 0; m < map->user_of_model.size(); ++m)
      if (map->user_of_model[m] == u) return static_cast<int>(m);
    throw InputError(what + ": joint '" + user->names[u] +
                     "' has no counterpart on the model's rig (map it with a rig map, or constrain a mapped joint)");
  }
};

MotionConstraints map_keys(const MotionConstraints& c, const ConstraintMapping& m) {
  MotionConstraints out;
  for (const PoseKey& k : c.keys) {
    PoseKey mk = k;
    mk.frame = m.frame(k.frame);
    if (!out.keys.empty() && out.keys.back().frame >= mk.frame) continue;
    if (k.rotations && !k.joints.empty()) {
      mk.joints = m.joints(k.joints);
      // Only joints the model lacks: what is left is the root position, if any.
      if (mk.joints.empty()) {
        if (!k.root_position) continue;
        mk.rotations = false;
      }
    }
    out.keys.push_back(mk);
  }
  return out;
}

MotionConstraints map_constraints(const MotionConstraints& c, const ConstraintMapping& m) {
  MotionConstraints out = map_keys(c, m);
  for (const EffectorTarget& t : c.effectors) {
    EffectorTarget mt = t;
    mt.frame = m.frame(t.frame);
    mt.joint = m.joint(t.joint, "the target at frame " + std::to_string(t.frame));
    mt.position = t.position * m.position_scale;
    out.effectors.push_back(mt);
  }
  for (const ContactPin& p : c.contacts) {
    ContactPin mp = p;
    mp.joint = m.joint(p.joint, "the contact on frames " + std::to_string(p.first) + ".." + std::to_string(p.last));
    mp.first = m.first_frame(p.first);
    mp.last = m.last_frame(p.last);
    if (mp.first < mp.last) out.contacts.push_back(mp);
  }
  for (const TrajectoryPoint& r : c.trajectory) {
    TrajectoryPoint mr = r;
    mr.frame = m.frame(r.frame);
    mr.x *= m.position_scale;
    mr.z *= m.position_scale;
    if (out.trajectory.empty() || out.trajectory.back().frame < mr.frame) out.trajectory.push_back(mr);
  }
  return out;
}

// The keys of `constraints` made exact in `out` (a solution on `input`'s rig
// and rate): per joint, the residual at the keys that give it spread linearly
// between them.
void match_keys(const Motion& input, const MotionConstraints& constraints, Motion* out) {
  const Motion solution = *out;
  for (int j = 0; j < input.num_joints(); ++j) {
    std::vector<int> frames;
    for (size_t k = 0; k < constraints.keys.size(); ++k)
      if (constraints.key_has_joint(k, j)) frames.push_back(constraints.keys[k].frame);
    spread_rotation_residual(input, solution, j, frames, ResidualRamp::Linear, out);
  }
  std::vector<int> root;
  for (const PoseKey& k : constraints.keys)
    if (k.root_position) root.push_back(k.frame);
  spread_root_residual(input, solution, root, ResidualRamp::Linear, out);
}

std::vector<int> key_frames_of(const MotionConstraints& c) {
  std::vector<int> frames;
  for (const PoseKey& k : c.keys)
    if (k.rotations && k.joints.empty()) frames.push_back(k.frame);
  return frames;
}

bool has_full_rotation_key(const MotionConstraints& c) {
  for (const PoseKey& k : c.keys)
    if (k.rotations && k.joints.empty()) return true;
  return false;
}

// The ground under `motion` (on the model's rig) seen from the frames
// `known`; a key in the air within a second of one on the ground does not lift it.
std::vector<double> model_ground(const Motion& motion, const std::vector<int>& known,
                                 const runtime::NemfRuntime& prior) {
  return ground_heights(motion, known, prior.rig(), static_cast<int>(std::lround(prior.config().fps)));
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

namespace {

// Throws unless the context has the model's rig anatomy (another rig than the
// model's needs it).
void require_anatomy(const Skeleton& input, const TaskContext& ctx) {
  if (!ctx.model_anatomy) {
    const std::string what = "the motion has " + std::to_string(input.num_joints()) +
                             " joints on another rig than the model's (" +
                             std::to_string(ctx.model->rig().num_joints()) + " joints), and ";
    if (!ctx.model_anatomy_error.empty())
      throw ModelMissingError(what + "the model's rig anatomy file did not load: " + ctx.model_anatomy_error);
    throw InputError(what + "the model has no rig anatomy to retarget with (" + kRigAnatomyFileName +
                     " next to the model file)");
  }
}

}  // namespace

std::optional<RigMap> check_model_rig(const Skeleton& input, const TaskContext& ctx) {
  if (!ctx.model || input.same_as(ctx.model->rig().skeleton)) return std::nullopt;
  require_anatomy(input, ctx);
  return model_rig_map(input, ctx);
}

Retargeter model_retargeter(const Motion& input, const std::vector<int>& known, const TaskContext& ctx,
                            std::optional<RigMap> map) {
  const Skeleton& model = require_prior(ctx, "this method").rig().skeleton;
  require_anatomy(input.skeleton, ctx);
  if (!map) map = model_rig_map(input.skeleton, ctx);
  RigAnatomy user = user_rig_anatomy(input, map->user_parts, known);
  return Retargeter(input.skeleton, model, std::move(*map), std::move(user), *ctx.model_anatomy);
}

Motion match_known_frames(const Motion& out_in, const Motion& input, const std::vector<int>& known) {
  Motion out = out_in;
  for (int j = 0; j < out.num_joints(); ++j)
    spread_rotation_residual(input, out_in, j, known, ResidualRamp::Linear, &out);
  spread_root_residual(input, out_in, known, ResidualRamp::Linear, &out);
  return out;
}

Motion complete_on_model_rig(const Motion& input, const std::vector<int>& known, const TaskContext& ctx,
                             const CompleteFn& complete, const std::optional<RigMap>& map) {
  if (!needs_model_rig(input, ctx)) return complete(input, known);
  const runtime::NemfRuntime& prior = require_prior(ctx, "this method");
  const double model_fps = prior.config().fps;
  const bool native = input.skeleton.same_as(prior.rig().skeleton);
  // The reference: interpolation between the known frames on the user's rig
  // (what joints the model lacks follow; reads only known frames).
  const Motion reference = interpolate_motion(input, known);
  std::optional<Retargeter> rig;
  if (!native) rig.emplace(model_retargeter(input, known, ctx, map));
  Motion on_model = native ? reference : rig->to_model(reference);
  const std::vector<double> ground = model_ground(on_model, known, prior);
  shift_root_heights(&on_model, ground, -1.0);

  Motion result;
  if (same_frame_rate(input.fps, model_fps)) {
    result = complete(on_model, known);
  } else {
    const int frames = model_rate_frames(input.num_frames(), input.fps, model_fps);
    Motion at_rate = resample_cubic(on_model, model_fps, frames);
    const std::vector<int> rate_known =
        model_rate_known(known, input.fps, model_fps, frames, on_model, &at_rate);
    const Motion solved = complete(at_rate, rate_known);
    result = resample_cubic(solved, input.fps, input.num_frames());
  }
  shift_root_heights(&result, ground, 1.0);
  Motion back = native ? result : rig->to_user(result, reference);
  back.skeleton = input.skeleton;
  back.fps = input.fps;
  return match_known_frames(back, input, known);
}

Motion complete_constrained_on_model_rig(const Motion& input, const MotionConstraints& constraints,
                                         const TaskContext& ctx, const ConstrainedFn& complete,
                                         std::vector<std::string>* warnings, const std::optional<RigMap>& map) {
  const runtime::NemfRuntime& prior = require_prior(ctx, "this method");
  const Skeleton& model = prior.rig().skeleton;
  const double model_fps = prior.config().fps;
  // The model's joints and hierarchy: the solvers work on the input's own bone lengths.
  const bool native = input.skeleton.names == model.names && input.skeleton.parents == model.parents;
  const bool same_rate = same_frame_rate(input.fps, model_fps);
  if (native && same_rate) return complete(input, constraints);
  if (!native && !has_full_rotation_key(constraints))
    throw InputError("on another rig than the model's, at least one key must give the whole pose (every joint's "
                     "rotation): the joints no key gives have nothing to retarget from");
  const Motion reference = fill_by_interpolation(input, constraints);
  std::optional<Retargeter> rig;
  if (!native) rig.emplace(model_retargeter(input, key_frames_of(constraints), ctx, map));
  Motion on_model = native ? reference : rig->to_model(reference);

  ConstraintMapping mapping;
  mapping.model_frames = same_rate ? input.num_frames() : model_rate_frames(input.num_frames(), input.fps, model_fps);
  mapping.frame_scale = same_rate ? 1.0 : model_fps / input.fps;
  mapping.position_scale = native ? 1.0 : rig->scale();
  mapping.user = &input.skeleton;
  if (!native) mapping.map = &rig->map();
  const MotionConstraints on_model_constraints = map_constraints(constraints, mapping);
  if (!same_rate) on_model = resample_cubic(on_model, model_fps, mapping.model_frames);

  Motion result = complete(on_model, on_model_constraints);
  if (!same_rate) result = resample_cubic(result, input.fps, input.num_frames());
  Motion back = native ? result : rig->to_user(result, reference);
  back.skeleton = input.skeleton;
  back.fps = input.fps;
  match_keys(input, constraints, &back);
  reach_effectors(constraints, kDefaultEffectorFalloff, &back);
  for (std::string& w : pin_contacts(constraints, kDefaultContactRamp, &back)) warnings->push_back(std::move(w));
  return back;
}

Motion resample_on_model_rig(const Motion& input, double fps, int frames, const TaskContext& ctx,
                             const ResampleFn& resample, const std::optional<RigMap>& map) {
  if (!ctx.model || input.skeleton.same_as(ctx.model->rig().skeleton)) return resample(input, fps, frames);
  const Retargeter rig = model_retargeter(input, {}, ctx, map);
  Motion on_model = rig.to_model(input);
  std::vector<int> all(static_cast<size_t>(input.num_frames()));
  for (int f = 0; f < input.num_frames(); ++f) all[f] = f;
  const std::vector<double> ground = model_ground(on_model, all, *ctx.model);
  shift_root_heights(&on_model, ground, -1.0);
  Motion result = resample(on_model, fps, frames);
  // The ground at the output's times: the same time span, linear between input frames.
  std::vector<double> out_ground(static_cast<size_t>(frames));
  for (int k = 0; k < frames; ++k) {
    const double t = frames > 1 ? double(k) * (input.num_frames() - 1) / (frames - 1) : 0.0;
    const int a = std::min(static_cast<int>(t), input.num_frames() - 1), b = std::min(a + 1, input.num_frames() - 1);
    out_ground[k] = ground[a] + (t - a) * (ground[b] - ground[a]);
  }
  shift_root_heights(&result, out_ground, 1.0);
  Motion back = rig.to_user(result, resample_cubic(input, fps, frames));
  back.skeleton = input.skeleton;
  return back;
}

}  // namespace mf
