// The task entry points behind the C API (and so the CLI, the batch mode and
// Python) and the benchmark: the one place where a request is validated and
// dispatched to a method by name. Bad input throws mf::InputError with a
// message for the user; a method whose model is not loaded throws its
// subclass mf::ModelMissingError (prior/motion/errors.h). (Methods keep the
// few checks they need for callers that use them directly, like the benchmark.)
//
// Methods are registered in tasks/methods/method.h. An empty method name means
// default_method(ctx); an unregistered name throws InputError listing the
// available ones; a method that needs the prior throws ModelMissingError when
// the context has no model, or the transformer it needs
// (Method::needs_inbetweener: require_inbetweener() of
// tasks/transformer/inbetweener_files.h); a method that does not support the task throws
// InputError saying so. Motions on another rig or at another frame rate than
// the model's go through the model-rig adapter (tasks/context/model_rig.h).
#pragma once

#include <string>
#include <vector>

#include "prior/motion/motion.h"
#include "tasks/constraints/constraint_report.h"
#include "tasks/constraints/motion_constraints.h"
#include "tasks/methods/method.h"

namespace mf {

/// Every registered method (baselines, the prior's, the solvers', the
/// transformers'), in a fixed order.
const std::vector<Method>& registered_methods();
/// Names of the registered methods, e.g. {"interp", "zerovel", ...}.
std::vector<std::string> available_methods();
/// What runs when no method is given for in-betweening and gap filling: the
/// best measured method that can run in this context ("nemf-detail" with the
/// prior and the two-stage transformer, "nemf" with the prior alone, "interp"
/// without a model). With `trajectory` (constraints that carry one) and the
/// keyframe transformer: "nemf-refine".
std::string default_method(const TaskContext& ctx = {}, bool trajectory = false);
/// The same for resampling: "prior" with a model, "quintic" without one.
std::string default_resample_method(const TaskContext& ctx = {});

/// The method `method` names (empty: default_method(ctx)), checked against
/// the context: InputError listing the available methods for an unknown
/// name, ModelMissingError when it needs the prior or a transformer that
/// `ctx` does not hold.
const Method& resolve_method(const std::string& method, const TaskContext& ctx, bool trajectory = false);

/// Throws InputError unless: at least two keyframes, strictly increasing (so
/// sorted and unique), every one in [0, frames). The message names the
/// offending keyframe (out of range, given twice, or out of order).
void validate_keyframes(const std::vector<int>& keyframes, int frames);

/// Known frames of a gap fill: every frame outside [a, b), in increasing order.
/// Throws InputError unless 1 <= a < b <= frames - 1 (the gap is non-empty and
/// has a known frame on each side).
std::vector<int> known_frames_outside_gap(int frames, int a, int b);

/// Output frame count of resampling `frames` frames from fps_in to fps_out,
/// keeping the time span: (frames - 1) * fps_out / fps_in + 1. A value within
/// 1e-5 relative of an integer counts as that integer (BVH frame times carry
/// about six significant digits: 0.0333333 s must still mean 30 fps); otherwise
/// it is rounded down and *rounded (if non-null) is set to true, else to false.
/// Throws InputError when an fps is not finite and positive, frames < 1, or the
/// result would exceed 10 million frames.
int resampled_frame_count(int frames, double fps_in, double fps_out, bool* rounded);

/// The task entry points below validate a request once, here: the method and
/// the models it needs (resolve_method), the motion, the known frames, and a
/// motion on another rig than the model's (check_model_rig of
/// tasks/context/model_rig.h); then they make the first progress report (which also
/// honours a cancel token cancelled before the call) and run the method.
/// Errors: InputError (bad input), ModelMissingError (a model the request
/// needs is not loaded), CancelledError.

/// Sparse-keyframe in-betweening: the output has the input's length and fps;
/// known frames are `keyframes` (validated with validate_keyframes()), the
/// others are never read. Known frames are copied exactly. What the method
/// says about its path (for instance that it fell back to interpolation,
/// tasks/latent/fallback.h) is appended to *warnings when given.
Motion run_inbetween(const Motion& input, const std::vector<int>& keyframes, const std::string& method,
                     const TaskContext& ctx = {}, std::vector<std::string>* warnings = nullptr);

/// Gap filling: frames a..b-1 unknown, all others known (as run_inbetween with
/// known_frames_outside_gap()).
Motion run_fill(const Motion& input, int a, int b, const std::string& method, const TaskContext& ctx = {},
                std::vector<std::string>* warnings = nullptr);

/// Resampling to `fps`, keeping the time span; the output's fps is `fps` and
/// its length resampled_frame_count(). If the frame count had to be rounded
/// down, a sentence saying so is appended to *warnings (if non-null).
Motion run_resample(const Motion& input, double fps, const std::string& method,
                    std::vector<std::string>* warnings, const TaskContext& ctx = {});

/// Runs `complete` of a method on explicit known frames (validated like
/// keyframes): the common path of run_inbetween and run_fill.
Motion run_known_frames(const Motion& input, const std::vector<int>& known, const std::string& method,
                        const TaskContext& ctx = {}, std::vector<std::string>* warnings = nullptr);

/// Most alternatives one request may ask for.
inline constexpr int kMaxAlternatives = 16;

/// What run_constrained() returns: the method's solution first, then the
/// alternatives; how well each meets the constraints (measured on it); and a
/// warning for each constraint that could not hold exactly (a target out of
/// reach, a pin that contradicts keys), naming the frames involved.
struct ConstrainedResult {
  std::string method;  ///< the method that ran (the default one when none was named)
  std::vector<Motion> motions;
  std::vector<ConstraintReport> reports;
  std::vector<std::string> warnings;
};

/// run_constrained() warns when the result misses its trajectory by more than
/// this on the ground on any followed row (a few times what the trajectory
/// energy leaves on ground-truth rows, docs/CONSTRAINTS.md)...
inline constexpr double kTrajectoryWarnCm = 10.0;
/// ... or by more than this in facing.
inline constexpr double kTrajectoryWarnDeg = 20.0;

/// Completes `input` under `constraints` (partial keys, end-effector targets,
/// contact pins, a trajectory; validated here: frames and joints in range, finite values,
/// at least one key fixing the root) with `alternatives` (0..kMaxAlternatives)
/// more solutions from other starts, deterministic for the context's seed.
/// Whole-pose keys alone without alternatives take run_known_frames()'s path
/// (any rig, any rate); anything else needs a method with
/// Method::complete_constrained (the latent solvers; "interp" without
/// alternatives). The model's methods serve any rig and rate the model can
/// retarget from (tasks/context/model_rig.h complete_constrained_on_model_rig(); on
/// another rig one key must give the whole pose). Known values come out
/// exactly as given. A trajectory needs a method with
/// Method::follows_trajectory (the latent solvers): any other throws
/// InputError naming those that can, and a result that misses the trajectory
/// by more than kTrajectoryWarnCm / kTrajectoryWarnDeg gets a warning.
ConstrainedResult run_constrained(const Motion& input, const MotionConstraints& constraints, const std::string& method,
                                  int alternatives, const TaskContext& ctx = {});

}  // namespace mf
