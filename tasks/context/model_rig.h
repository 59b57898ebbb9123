// Methods that use the learned models run on the model's rig at the model's
// frame rate. These adapters let them serve a motion on any humanoid rig, in any
// unit (the motion is in metres already) and at any frame rate: the input is
// retargeted to the model's rig (prior/rig/retarget.h) and resampled to the
// model's rate, the method runs, and its result comes back on the user's rig at
// the input's rate (both resamplings by the Catmull-Rom spline of
// resample_cubic(), tasks/constraints/interpolation_fill.h). Joints the model lacks (fingers, twist bones, props) come
// back interpolated between the known frames; known frames are returned exactly
// as given; unknown input frames are never read.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "prior/motion/motion.h"
#include "prior/rig/retarget.h"
#include "tasks/constraints/motion_constraints.h"
#include "tasks/context/task_context.h"

namespace mf {

/// The most frames any change of frame rate may produce: resampling a motion
/// (resampled_frame_count(), tasks/methods/jobs.h) and a motion's span at the model's
/// rate when a method solves there. More is refused with an InputError.
inline constexpr double kMaxResampledFrames = 10'000'000;

/// File name of the prior's rig anatomy, next to the prior's model file.
inline constexpr char kRigAnatomyFileName[] = "motionfield-rig.json";

/// The rig anatomy in `kRigAnatomyFileName` next to `prior_file` for the
/// skeleton `model`; null when there is no such file. Throws InputError (naming
/// the file) when it exists but cannot be read or does not fit the skeleton.
std::shared_ptr<const RigAnatomy> load_rig_anatomy_next_to(const std::string& prior_file, const Skeleton& model);

/// True when `input` cannot go to a model method as it is: another skeleton
/// than the prior's, or another frame rate than the model's.
bool needs_model_rig(const Motion& input, const TaskContext& ctx);

/// The map of `user` onto the prior's skeleton with ctx.rig_map applied
/// (map_rig; its errors are prefixed with ctx.rig_map_source). Throws
/// ModelMissingError without a model.
RigMap model_rig_map(const Skeleton& user, const TaskContext& ctx);

/// Checks, before a model method runs, that a motion on `input` can be
/// served, and returns its map onto the model's rig, which the adapters below
/// take so that a request maps its rig once: nullopt for the prior's own
/// skeleton (or without a prior); else the model needs its rig anatomy
/// (ModelMissingError when the anatomy file next to the prior did not load,
/// InputError when there is none) and the rig must map onto the prior's
/// (model_rig_map's InputError).
std::optional<RigMap> check_model_rig(const Skeleton& input, const TaskContext& ctx);

/// A retargeter from `input`'s rig to the model's, its anatomy measured on the
/// frames `known` of `input` (all when empty), with `map` (check_model_rig's
/// for this skeleton) or, without one, the map made here. Throws InputError
/// when the rig cannot be mapped or the context has no model anatomy.
Retargeter model_retargeter(const Motion& input, const std::vector<int>& known, const TaskContext& ctx,
                            std::optional<RigMap> map = std::nullopt);

using CompleteFn = std::function<Motion(const Motion& input, const std::vector<int>& known)>;
using ResampleFn = std::function<Motion(const Motion& input, double fps, int frames)>;
using ConstrainedFn = std::function<Motion(const Motion& input, const MotionConstraints& constraints)>;

/// Runs `complete` (a method on the model's rig and rate) for `input` with
/// known frames `known` (validated by the caller). The adapters take the
/// request's rig map (check_model_rig()) when the caller has it; without it
/// they map the rig themselves.
Motion complete_on_model_rig(const Motion& input, const std::vector<int>& known, const TaskContext& ctx,
                             const CompleteFn& complete, const std::optional<RigMap>& map = std::nullopt);

/// Runs `complete` (a constrained method on the model's rig and rate) for
/// `input` under `constraints` (validated against `input` by the caller).
/// A motion with the model's joint names and hierarchy at the model's rate
/// goes to `complete` as it is (its bone lengths may differ). Otherwise the
/// reference (fill_by_interpolation() of the keys, on the user's rig) is
/// retargeted and resampled to the model's rate, and the constraints follow:
/// key, target and trajectory frames to the nearest model frame, pin ends
/// rounded outwards (keys
/// and trajectory rows that land on a frame taken already are dropped, pins
/// shorter than two model frames too), joints through the rig map (a partial
/// key keeps the model joints its joints play; target and pin joints must be
/// mapped: InputError otherwise), positions scaled by the retargeter's scale.
/// The result comes back on the user's rig at the input's rate and is made
/// exact there: each key's values with their residual spread linearly to the
/// neighbouring keys of the same joint, then end-effector IK and contact pins
/// on the user's own bones (their warnings are appended to `warnings`).
/// InputError when a key-free joint would be needed: on another rig, at least
/// one key must give every rotation.
Motion complete_constrained_on_model_rig(const Motion& input, const MotionConstraints& constraints,
                                         const TaskContext& ctx, const ConstrainedFn& complete,
                                         std::vector<std::string>* warnings,
                                         const std::optional<RigMap>& map = std::nullopt);

/// Runs `resample` (a method on the model's rig; any input rate) for `input`.
Motion resample_on_model_rig(const Motion& input, double fps, int frames, const TaskContext& ctx,
                             const ResampleFn& resample, const std::optional<RigMap>& map = std::nullopt);

/// Corrects `out` so that its known frames equal `input`'s: the difference at
/// each known frame (per joint rotation, root position) is interpolated
/// linearly over the frames between known ones (held before the first and
/// after the last), then the known frames are copied exactly
/// (tasks/constraints/residuals.h, ResidualRamp::Linear). Same skeleton, frames and fps.
Motion match_known_frames(const Motion& out, const Motion& input, const std::vector<int>& known);

}  // namespace mf
