#include "tasks/context/task_context.h"

#include "prior/inbetween/inbetweener.h"
#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/runtime/inbetween_runtime.h"

namespace mf {

const NemfModel& require_prior(const TaskContext& ctx, const std::string& what) {
  if (!ctx.model) throw ModelMissingError(what + " needs a model (the prior), and none is loaded");
  return *ctx.model;
}

void ModelSet::add_inbetweener(std::shared_ptr<const InbetweenModel> m,
                               std::shared_ptr<const runtime::InbetweenerRuntime> twin) {
  const std::string kind = m->kind();
  if (twin && twin->kind() != kind)
    throw std::invalid_argument("add_inbetweener: a '" + twin->kind() + "' runtime given with a '" + kind + "' model");
  inbetweeners[kind] = std::move(m);
  if (twin) {
    inbetweener_runtimes[kind] = std::move(twin);
  } else {
    inbetweener_runtimes.erase(kind);
  }
  inbetweener_errors.erase(kind);
}

}  // namespace mf
