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

void check_model_skeleton(const RigInfo& rig, const Skeleton& skeleton, const std::string& whose) {
  if (skeleton.num_joints() != rig.num_joints() || skeleton.names != rig.skeleton.names ||
      skeleton.parents != rig.skeleton.parents) {
    throw InputError("the " + whose + "'s skeleton does not match the model's: " +
                     std::to_string(skeleton.num_joints()) + " joints given, the model has " +
                     std::to_string(rig.num_joints()) + " (joint names and parents must agree)");
  }
}

}  // namespace mf
