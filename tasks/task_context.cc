#include "tasks/task_context.h"

#include "prior/model/nemf.h"
#include "prior/motion/errors.h"

namespace mf {

const NemfModel& require_prior(const TaskContext& ctx, const std::string& what) {
  if (!ctx.model) throw ModelMissingError(what + " needs the prior, and no model is loaded");
  return *ctx.model;
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
