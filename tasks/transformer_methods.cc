#include "tasks/transformer_methods.h"

#include "prior/inbetween/inbetweener.h"

namespace mf {
namespace {

Method transformer_method(const std::string& name, const std::string& description, const std::string& kind,
                          int stage) {
  Method m;
  m.name = name;
  m.description = description;
  m.needs_model = true;
  m.needs_inbetweener = kind;
  m.complete = [name, kind, stage](const Motion& input, const std::vector<int>& known, const TaskContext& ctx) {
    const InbetweenModel& model = require_inbetweener(ctx, kind, "method '" + name + "'");
    return inbetweener_fill(model, stage, input, MotionConstraints::full_pose(known), LongGapPolicy::Throw);
  };
  return m;
}

}  // namespace

std::vector<Method> transformer_methods() {
  return {transformer_method("context", "two-stage transformer, Context Transformer only (one pass)", kTwoStageKind, 0),
          transformer_method("detail", "two-stage transformer, Context + Detail Transformer (one pass)", kTwoStageKind,
                             1),
          transformer_method("citl", "CITL transformer (one pass)", kCitlKind, -1)};
}

}  // namespace mf
