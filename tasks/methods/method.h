// Methods: the named algorithms behind every task ("interp", "zerovel", the
// prior's methods, the solvers, the transformers). They run in a TaskContext
// (tasks/context/task_context.h); tasks/methods/jobs.h validates input and dispatches to them
// by name.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "prior/motion/motion.h"
#include "tasks/constraints/motion_constraints.h"
#include "tasks/context/task_context.h"

namespace mf {

/// What a method says about a completion besides its motion.
struct CompletionNotes {
  /// Sentences for the user (which path ran and why).
  std::vector<std::string> warnings;
  /// True when the method judged its own result implausible for the whole
  /// input and returned interpolation of the known frames instead
  /// (tasks/latent/fallback.h): the caller then returns the user rig's own
  /// interpolation, exactly.
  bool interpolated = false;
};

struct Method {
  std::string name;
  std::string description;
  bool needs_model = false;
  /// Kind of in-betweener the method needs besides the prior (an
  /// InbetweenerKind name, see ModelSet::inbetweeners); empty for none.
  std::string needs_inbetweener;
  /// Completes a motion from its known frames (sorted, unique, at least two,
  /// in range): every other frame is produced, known frames come out as given.
  /// Unknown input frames must never be read. `notes` (may be null) receives
  /// what the method says about the path it took. Null when unsupported.
  std::function<Motion(const Motion& input, const std::vector<int>& known, const TaskContext& ctx,
                       CompletionNotes* notes)>
      complete;
  /// Completes a motion under any constraints (partial keys, end-effector
  /// targets, contact pins), validated by the caller. `variant` 0 is the
  /// method's answer; variant v > 0 the v-th alternative (another start, the
  /// same for the same context seed). Warnings of constraints that could not
  /// hold exactly are appended to *warnings. Null when the method takes only
  /// whole-pose keys (complete).
  std::function<Motion(const Motion& input, const MotionConstraints& c, int variant, const TaskContext& ctx,
                       std::vector<std::string>* warnings)>
      complete_constrained;
  /// True when complete_constrained follows MotionConstraints::trajectory;
  /// run_constrained() refuses a trajectory for the other methods (naming
  /// the ones that can) rather than ignoring it.
  bool follows_trajectory = false;
  /// Resamples to `fps` with exactly `frames` output frames at times i / fps,
  /// appending what the user should know to *warnings (never null). Null when
  /// unsupported.
  std::function<Motion(const Motion& input, double fps, int frames, const TaskContext& ctx,
                       std::vector<std::string>* warnings)>
      resample;
};

/// The method families, each defined beside its implementation.
std::vector<Method> baseline_methods();  // tasks/methods/baselines.cc
std::vector<Method> prior_methods();     // tasks/methods/prior_methods.cc
std::vector<Method> solver_methods();    // tasks/methods/solver_methods.cc
std::vector<Method> transformer_methods();  // tasks/methods/transformer_methods.cc

}  // namespace mf
