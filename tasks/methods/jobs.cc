#include "tasks/methods/jobs.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include "prior/inbetween/inbetween_config.h"
#include "prior/runtime/nemf_runtime.h"
#include "prior/motion/errors.h"
#include "tasks/constraints/interpolation_fill.h"
#include "tasks/constraints/motion_constraints.h"
#include "tasks/context/model_rig.h"
#include "tasks/transformer/inbetweener_files.h"

namespace mf {
namespace {

std::string method_list() {
  std::string s;
  for (const std::string& m : available_methods()) s += (s.empty() ? "" : ", ") + m;
  return s;
}

void check_motion(const Motion& input) {
  if (input.num_frames() < 1) throw InputError("the input motion has no frames");
  if (input.rotations.size() != static_cast<size_t>(input.num_frames()) * input.num_joints())
    throw InputError("the input motion's rotation count does not match its frames and joints");
  if (!(std::isfinite(input.fps) && input.fps > 0)) throw InputError("the input motion's fps must be finite and positive");
}

// What a request asks of its method.
enum class Ask { kComplete, kResample };

// A request prepared once: its method, and the map of its motion's rig onto
// the model's when the method needs the model and the rig is another (which
// the model-rig adapter then takes instead of mapping again).
struct Prepared {
  const Method& method;
  std::optional<RigMap> rig_map;
};

// The method of a request, checked once with the motion, in the order a user
// thinks: the method exists and does the task, then the motion, then its rig
// when the method needs the model (the frames come after, by the callers).
Prepared prepare(const std::string& method, const Motion& input, const TaskContext& ctx, Ask ask) {
  const Method& m = resolve_method(method, ctx);
  if (ask == Ask::kComplete && !m.complete)
    throw InputError("method '" + m.name + "' does not do in-betweening or gap filling");
  if (ask == Ask::kResample && !m.resample) throw InputError("method '" + m.name + "' does not do resampling");
  check_motion(input);
  return {m, m.needs_model ? check_model_rig(input.skeleton, ctx) : std::nullopt};
}

// The first progress report of a validated request; it also honours a cancel
// token cancelled before the call.
void start(const TaskContext& ctx) { ctx.report(TaskProgress{}); }

// Runs `complete` of `m` on validated input (the common end of
// run_known_frames and run_fill): methods that need the model run on the
// model's rig and rate (tasks/context/model_rig.h). A method that fell back to
// interpolation everywhere gets the input rig's own interpolation, exactly.
Motion complete_with(const Prepared& request, const Motion& input, const std::vector<int>& known,
                     const TaskContext& ctx, std::vector<std::string>* warnings) {
  start(ctx);
  const Method& m = request.method;
  CompletionNotes notes;
  auto complete = [&](const Motion& in, const std::vector<int>& k) { return m.complete(in, k, ctx, &notes); };
  Motion out = !m.needs_model ? m.complete(input, known, ctx, &notes)
                              : complete_on_model_rig(input, known, ctx, complete, request.rig_map);
  if (notes.interpolated) out = interpolate_motion(input, known);
  if (warnings)
    for (std::string& w : notes.warnings) warnings->push_back(std::move(w));
  return out;
}

std::vector<int> key_frames(const MotionConstraints& c) {
  std::vector<int> frames;
  for (const PoseKey& k : c.keys) frames.push_back(k.frame);
  return frames;
}

// Warnings for targets the output misses by more than a centimetre.
void warn_missed_targets(const Motion& out, const MotionConstraints& c, std::vector<std::string>* warnings) {
  const GlobalPose pose = forward_kinematics(out);
  for (const EffectorTarget& t : c.effectors) {
    const double cm = (pose.position(t.frame, t.joint) - t.position).norm() * 100.0;
    if (cm <= 1.0 || t.weight == 0.0) continue;
    std::ostringstream msg;
    msg.precision(3);
    msg << "the target of joint '" << out.skeleton.names[t.joint] << "' at frame " << t.frame << " is missed by " << cm
        << " cm (out of the body's reach, or a key at that frame fixes the joint's chain)";
    warnings->push_back(msg.str());
  }
}

// Warnings for contact pins the output lets slide by more than half a centimetre.
void warn_sliding_pins(const Motion& out, const MotionConstraints& c, std::vector<std::string>* warnings) {
  for (const ContactPin& p : c.contacts) {
    MotionConstraints one;
    one.contacts = {p};
    const double cm = contact_error(out, one).max_cm;
    if (cm <= 0.5) continue;
    std::ostringstream msg;
    msg.precision(3);
    msg << "the contact of joint '" << out.skeleton.names[p.joint] << "' on frames " << p.first << ".." << p.last
        << " slides up to " << cm << " cm (the body moves beyond the limb's reach, or keys move the joint)";
    warnings->push_back(msg.str());
  }
}

// Refuses a trajectory for a method that cannot follow one, naming those that can.
void check_follows_trajectory(const Method& m, const MotionConstraints& c) {
  if (c.trajectory.empty() || m.follows_trajectory) return;
  std::string can;
  for (const Method& a : registered_methods()) {
    if (a.follows_trajectory) can += (can.empty() ? "" : ", ") + a.name;
  }
  throw InputError("method '" + m.name + "' cannot follow a trajectory; the methods that can: " + can);
}

// One warning when the output misses the trajectory it follows by more than
// kTrajectoryWarnCm on the ground or kTrajectoryWarnDeg in facing on any row.
void warn_missed_trajectory(const Motion& out, const MotionConstraints& c, const Eigen::Vector3d& root_forward,
                            std::vector<std::string>* warnings) {
  const TrajectoryError e = trajectory_error(out, c, root_forward);
  if (e.rows == 0 || (e.max_cm <= kTrajectoryWarnCm && e.facing_max_deg <= kTrajectoryWarnDeg)) return;
  std::ostringstream msg;
  msg.precision(3);
  msg << "the trajectory is missed by up to " << e.max_cm << " cm on the ground (mean " << e.mean_cm
      << " cm) and " << e.facing_max_deg << " degrees in facing (mean " << e.facing_mean_deg << ") over " << e.rows
      << " rows (a path the body cannot walk between the keys in the time given, or keys that contradict it)";
  warnings->push_back(msg.str());
}

}  // namespace

const std::vector<Method>& registered_methods() {
  static const std::vector<Method> methods = [] {
    std::vector<Method> all = baseline_methods();
    for (auto family : {prior_methods, solver_methods, transformer_methods}) {
      for (Method& m : family()) all.push_back(std::move(m));
    }
    return all;
  }();
  return methods;
}

std::vector<std::string> available_methods() {
  std::vector<std::string> names;
  for (const Method& m : registered_methods()) names.push_back(m.name);
  return names;
}

// Measured in docs/BENCHMARKS.md ("Latent solvers" and "Transformer
// in-betweeners"): L-BFGS started from the two-stage transformer beats the
// solver from interpolation, which beats interpolation, on L2P, L2Q, NPSS and
// foot skating at gaps of 15+ frames and keys 15+ frames apart (and ties it
// below).
// With a trajectory (docs/BENCHMARKS.md, "Long transitions"): the solver
// started from RefineNet, which reads the trajectory, follows it and drawn
// paths more closely and is the best or level on L2P from 60 to 180 frames.
std::string default_method(const TaskContext& ctx, bool trajectory) {
  if (trajectory && ctx.model && ctx.inbetweener(kKeyframeKind)) return "nemf-refine";
  if (ctx.model && ctx.inbetweener(kTwoStageKind)) return "nemf-detail";
  return ctx.model ? "nemf" : "interp";
}

std::string default_resample_method(const TaskContext& ctx) { return ctx.model ? "prior" : "quintic"; }

const Method& resolve_method(const std::string& method, const TaskContext& ctx, bool trajectory) {
  const std::string m = method.empty() ? default_method(ctx, trajectory) : method;
  for (const Method& a : registered_methods()) {
    if (a.name != m) continue;
    if (a.needs_model) require_prior(ctx, "method '" + m + "'");
    if (!a.needs_inbetweener.empty()) require_inbetweener(ctx, a.needs_inbetweener, "method '" + m + "'");
    return a;
  }
  throw InputError("unknown method '" + method + "' (available: " + method_list() + ")");
}

void validate_keyframes(const std::vector<int>& keyframes, int frames) {
  if (keyframes.size() < 2)
    throw InputError("at least two keyframes are required (got " + std::to_string(keyframes.size()) + ")");
  for (size_t i = 0; i < keyframes.size(); ++i) {
    const int k = keyframes[i];
    if (k < 0 || k >= frames)
      throw InputError("keyframe " + std::to_string(k) + " is out of range: the input has " + std::to_string(frames) +
                       " frames (0.." + std::to_string(frames - 1) + ")");
    if (i > 0) check_keyframe_order(keyframes[i - 1], k);
  }
}

std::vector<int> known_frames_outside_gap(int frames, int a, int b) {
  const std::string gap = std::to_string(a) + ":" + std::to_string(b);
  if (b <= a) throw InputError("gap " + gap + " is empty: it must be A:B with A < B (frames A..B-1 are filled)");
  if (a < 1) throw InputError("gap " + gap + " touches the first frame: frame 0 must stay known (A >= 1)");
  if (b > frames - 1)
    throw InputError("gap " + gap + " touches or passes the last frame: the input has " + std::to_string(frames) +
                     " frames, so B must be at most " + std::to_string(frames - 1));
  std::vector<int> known;
  known.reserve(static_cast<size_t>(frames - (b - a)));
  for (int f = 0; f < a; ++f) known.push_back(f);
  for (int f = b; f < frames; ++f) known.push_back(f);
  return known;
}

int resampled_frame_count(int frames, double fps_in, double fps_out, bool* rounded) {
  if (!(std::isfinite(fps_in) && fps_in > 0)) throw InputError("the input fps must be finite and positive");
  if (!(std::isfinite(fps_out) && fps_out > 0)) throw InputError("the target fps must be finite and positive");
  if (frames < 1) throw InputError("cannot resample a motion without frames");
  const double exact = static_cast<double>(frames - 1) * (fps_out / fps_in) + 1.0;
  const double nearest = std::round(exact);
  // BVH frame times carry about 6 significant digits (0.0333333 s), so a ratio
  // within 1e-5 relative of an integer count is taken as that integer.
  const bool integral = std::abs(exact - nearest) <= 1e-5 * std::max(1.0, exact);
  const double count = integral ? nearest : std::floor(exact);
  // Not `count > max`: a ratio fps_out / fps_in that overflows makes `exact`
  // infinite, or NaN for one frame (0 * inf), and NaN must not reach the cast.
  if (!(count <= kMaxResampledFrames)) {
    std::ostringstream msg;
    msg << "resampling " << frames << " frames from " << fps_in << " to " << fps_out << " fps would give more than "
        << static_cast<long long>(kMaxResampledFrames) << " frames";
    throw InputError(msg.str());
  }
  if (rounded) *rounded = !integral;
  return static_cast<int>(count);
}

Motion run_known_frames(const Motion& input, const std::vector<int>& known, const std::string& method,
                        const TaskContext& ctx, std::vector<std::string>* warnings) {
  const Prepared request = prepare(method, input, ctx, Ask::kComplete);
  validate_keyframes(known, input.num_frames());
  return complete_with(request, input, known, ctx, warnings);
}

Motion run_inbetween(const Motion& input, const std::vector<int>& keyframes, const std::string& method,
                     const TaskContext& ctx, std::vector<std::string>* warnings) {
  return run_known_frames(input, keyframes, method, ctx, warnings);
}

Motion run_fill(const Motion& input, int a, int b, const std::string& method, const TaskContext& ctx,
                std::vector<std::string>* warnings) {
  const Prepared request = prepare(method, input, ctx, Ask::kComplete);
  // Sorted, unique, in range and at least two (frame 0 and the last): valid keyframes.
  return complete_with(request, input, known_frames_outside_gap(input.num_frames(), a, b), ctx, warnings);
}

ConstrainedResult run_constrained(const Motion& input, const MotionConstraints& constraints, const std::string& method,
                                  int alternatives, const TaskContext& ctx) {
  if (alternatives < 0 || alternatives > kMaxAlternatives)
    throw InputError("alternatives must be between 0 and " + std::to_string(kMaxAlternatives) + " (got " +
                     std::to_string(alternatives) + ")");
  ConstrainedResult result;
  const Eigen::Vector3d root_forward = ctx.model ? ctx.model->rig().root_forward : Eigen::Vector3d::UnitZ();
  if (!constraints.beyond_full_poses() && alternatives == 0) {
    result.motions.push_back(run_known_frames(input, key_frames(constraints), method, ctx, &result.warnings));
    result.method = resolve_method(method, ctx).name;
  } else {
    const Method& m = resolve_method(method, ctx, !constraints.trajectory.empty());
    result.method = m.name;
    check_motion(input);
    check_follows_trajectory(m, constraints);
    if (!m.complete_constrained)
      throw InputError("method '" + m.name +
                       "' takes whole-pose keys only: partial keys, end-effector targets, contacts and alternatives "
                       "need a latent solver (nemf, nemf-detail, ...) or 'interp' (without alternatives)");
    const std::optional<RigMap> rig_map =
        m.needs_model ? check_model_rig(input.skeleton, ctx) : std::nullopt;  // the rig before the frames
    constraints.validate(input.num_frames(), input.num_joints());
    constraints.check_values(input);
    start(ctx);
    for (int v = 0; v <= alternatives; ++v) {
      auto solve = [&](const Motion& in, const MotionConstraints& c) {
        return m.complete_constrained(in, c, v, ctx, &result.warnings);
      };
      result.motions.push_back(m.needs_model ? complete_constrained_on_model_rig(input, constraints, ctx, solve,
                                                                                 &result.warnings, rig_map)
                                             : solve(input, constraints));
    }
    warn_missed_targets(result.motions.front(), constraints, &result.warnings);
    warn_sliding_pins(result.motions.front(), constraints, &result.warnings);
    warn_missed_trajectory(result.motions.front(), constraints, root_forward, &result.warnings);
  }
  for (const Motion& out : result.motions)
    result.reports.push_back(measure_constraints(input, constraints, out, root_forward));
  return result;
}

Motion run_resample(const Motion& input, double fps, const std::string& method, std::vector<std::string>* warnings,
                    const TaskContext& ctx) {
  const Prepared request =
      prepare(method.empty() ? default_resample_method(ctx) : method, input, ctx, Ask::kResample);
  const Method& m = request.method;
  bool rounded = false;
  const int frames = resampled_frame_count(input.num_frames(), input.fps, fps, &rounded);
  if (rounded && warnings) {
    std::ostringstream msg;
    const double span_in = (input.num_frames() - 1) / input.fps, span_out = (frames - 1) / fps;
    msg << "resampling " << input.num_frames() << " frames from " << input.fps << " to " << fps
        << " fps does not give a whole number of frames (" << (input.num_frames() - 1) * (fps / input.fps) + 1.0
        << "); rounded down to " << frames << " frames, so the output ends " << (span_in - span_out)
        << " s before the input's last frame";
    warnings->push_back(msg.str());
  }
  start(ctx);
  std::vector<std::string> notes;
  Motion out = m.needs_model ? resample_on_model_rig(
                                   input, fps, frames, ctx,
                                   [&](const Motion& in, double f, int n) { return m.resample(in, f, n, ctx, &notes); },
                                   request.rig_map)
                             : m.resample(input, fps, frames, ctx, &notes);
  if (warnings) warnings->insert(warnings->end(), notes.begin(), notes.end());
  return out;
}

}  // namespace mf
