#include "tasks/context/task_context.h"

#include "prior/motion/errors.h"
#include "prior/runtime/inbetween_runtime.h"
#include "prior/runtime/nemf_runtime.h"

namespace mf {

const runtime::NemfRuntime& require_prior(const TaskContext& ctx, const std::string& what) {
  if (!ctx.model) throw ModelMissingError(what + " needs a model (the prior), and none is loaded");
  return *ctx.model;
}

void ModelSet::add_inbetweener(std::shared_ptr<const runtime::InbetweenerRuntime> m) {
  const std::string kind = m->kind();
  inbetweeners[kind] = std::move(m);
  inbetweener_errors.erase(kind);
}

}  // namespace mf
