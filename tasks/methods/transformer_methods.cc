#include "tasks/methods/transformer_methods.h"

#include "prior/inbetween/inbetweener_kinds.h"
#include "prior/motion/errors.h"

namespace mf {
namespace {

Method transformer_method(const std::string& name, const std::string& description, const std::string& kind,
                          int stage, bool reads_trajectory, bool locks_feet) {
  Method m;
  m.name = name;
  m.follows_trajectory = reads_trajectory;
  m.description = description;
  m.needs_model = true;
  m.needs_inbetweener = kind;
  m.complete = [name, kind, stage, locks_feet](const Motion& input, const std::vector<int>& known,
                                               const TaskContext& ctx, CompletionNotes* notes) {
    const runtime::InbetweenerRuntime& model = require_inbetweener(ctx, kind, "method '" + name + "'");
    return inbetweener_fill(model, stage, input, MotionConstraints::full_pose(known), LongGapPolicy::Throw, locks_feet,
                            {ctx.interpolation_fallback, notes ? &notes->warnings : nullptr});
  };
  // Keys (full or partial) and a trajectory, one answer: inbetweener_fill reads both.
  m.complete_constrained = [name, kind, stage, locks_feet](const Motion& input, const MotionConstraints& c,
                                                           int variant, const TaskContext& ctx,
                                                           std::vector<std::string>* warnings) {
    if (variant > 0 || !c.effectors.empty() || !c.contacts.empty())
      throw InputError("method '" + name +
                       "' takes keys and a trajectory only: end-effector targets, contacts and alternatives need a "
                       "latent solver (nemf, nemf-" + name + ", ...)");
    const runtime::InbetweenerRuntime& model = require_inbetweener(ctx, kind, "method '" + name + "'");
    return inbetweener_fill(model, stage, input, c, LongGapPolicy::Throw, locks_feet,
                            {ctx.interpolation_fallback, warnings});
  };
  return m;
}

}  // namespace

std::vector<Method> transformer_methods() {
  std::vector<Method> methods;
  for (const InbetweenerKind& kind : inbetweener_kinds()) {
    for (size_t stage = 0; stage < kind.stages.size(); ++stage) {
      const InbetweenerStage& s = kind.stages[stage];
      methods.push_back(transformer_method(s.name, kind.title + ", " + s.description + " (one pass)", kind.name,
                                           static_cast<int>(stage), kind.reads_trajectory, kind.locks_feet));
    }
  }
  return methods;
}

}  // namespace mf
