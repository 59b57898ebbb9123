#include "tasks/context/task_context.h"

#include "prior/inbetween/inbetweener.h"
#include "prior/model/nemf.h"
#include "prior/motion/errors.h"

namespace mf {

const NemfModel& require_prior(const TaskContext& ctx, const std::string& what) {
  if (!ctx.model) throw ModelMissingError(what + " needs a model (the prior), and none is loaded");
  return *ctx.model;
}

void ModelSet::add_inbetweener(std::shared_ptr<const InbetweenModel> m) {
  const std::string kind = m->kind();
  inbetweeners[kind] = std::move(m);
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
