#include "training/keyframe_losses.h"

#include <ATen/ATen.h>

#include "prior/motion/errors.h"
#include "prior/motion/kinematics_torch.h"
#include "prior/model/representation.h"
#include "training/trainer_util.h"

namespace mf::training {

namespace {

constexpr double kKeyframePos = 1.0, kKeyframeTraj = 0.5, kScore = 1.0, kSmooth = 0.1;
constexpr double kRefinePos = 2.0, kRefineTraj = 0.2, kContact = 0.05, kFoot = 0.05;

// Frame-to-frame changes of the normalised pose, predicted against true, L1.
at::Tensor smooth_loss(const InbetweenModel& model, const at::Tensor& pose, const at::Tensor& target,
                       const at::Tensor& valid) {
  const int64_t T = pose.size(1);
  if (T < 2) return at::zeros({}, pose.options());
  at::Tensor scale = model.stats().pose_std.to(pose.options()).clamp_min(0.05);
  at::Tensor dp = (pose.narrow(1, 1, T - 1) - pose.narrow(1, 0, T - 1)) / scale;
  at::Tensor dt = (target.narrow(1, 1, T - 1) - target.narrow(1, 0, T - 1)) / scale;
  at::Tensor both = valid.narrow(1, 1, T - 1) * valid.narrow(1, 0, T - 1);
  return masked_mean((dp - dt).abs(), both);
}

// Speed of the foot joints of `pose` where the ground truth's foot is in contact.
at::Tensor foot_loss(const InbetweenModel& model, const at::Tensor& pose, const at::Tensor& contacts,
                     const at::Tensor& valid) {
  const RigInfo& rig = model.rig();
  const int64_t T = pose.size(1);
  if (!contacts.defined() || rig.num_feet() == 0 || T < 2) return at::zeros({}, pose.options());
  at::Tensor rotations, root;
  split_pose_features(pose, rig.num_joints(), &rotations, &root);
  at::Tensor offsets = offsets_tensor(rig.skeleton).to(pose.scalar_type());
  at::Tensor g = forward_kinematics(rig.skeleton.parents, offsets, rotations, root).positions;  // [B, T, J, 3]
  at::Tensor index = at::tensor(std::vector<int64_t>(rig.foot_joints.begin(), rig.foot_joints.end()), at::kLong);
  at::Tensor feet = g.index_select(2, index);                                      // [B, T, F, 3]
  at::Tensor speed = (feet.narrow(1, 1, T - 1) - feet.narrow(1, 0, T - 1)).norm(2, -1);  // [B, T-1, F]
  at::Tensor c = contacts.narrow(1, 1, T - 1) * contacts.narrow(1, 0, T - 1);
  at::Tensor both = (valid.narrow(1, 1, T - 1) * valid.narrow(1, 0, T - 1)).unsqueeze(-1) * c;
  return (speed * both).sum() / both.sum().clamp_min(1.0);
}

}  // namespace

at::Tensor trajectory_l1(const InbetweenModel& model, const at::Tensor& pose, const at::Tensor& trajectory,
                         const at::Tensor& valid) {
  at::Tensor rotations, root;
  split_pose_features(pose, model.rig().num_joints(), &rotations, &root);
  at::Tensor features = trajectory_features(rotations.select(2, 0), root, model.rig().root_forward);
  return masked_mean((features - trajectory.to(features.options())).abs(), valid);
}

KeyframeLosses keyframe_losses(const InbetweenModel& model, const InbetweenOutput& out, const KeyframeTargets& t) {
  if (!out.keyframe_poses.defined() || !out.keyframe_logits.defined() || out.stages.empty()) {
    throw InputError("keyframe_losses: the model did not return keyframe poses and scores");
  }
  KeyframeLosses L;
  L.keyframe_pos = inbetween_pose_loss(model, out.keyframe_poses, t.pose, t.valid);
  L.keyframe_traj = trajectory_l1(model, out.keyframe_poses, t.trajectory, t.valid);
  at::Tensor bce = at::binary_cross_entropy_with_logits(out.keyframe_logits, t.scores, {}, {}, at::Reduction::None);
  L.score = (bce * t.score_mask).sum() / t.score_mask.sum().clamp_min(1.0);
  L.smooth = smooth_loss(model, out.keyframe_poses, t.pose, t.valid);
  L.keyframe_total = kKeyframePos * L.keyframe_pos + kKeyframeTraj * L.keyframe_traj + kScore * L.score +
                     kSmooth * L.smooth;

  const at::Tensor& final_pose = out.stages.back();
  L.refine_pos = inbetween_pose_loss(model, final_pose, t.pose, t.valid, &L.refine_parts);
  L.refine_traj = trajectory_l1(model, final_pose, t.trajectory, t.valid);
  L.contact = at::zeros({}, final_pose.options());
  if (out.contact_logits.defined() && t.contacts.defined()) {
    at::Tensor c = at::binary_cross_entropy_with_logits(out.contact_logits, t.contacts, {}, {}, at::Reduction::None);
    L.contact = masked_mean(c, t.valid);
  }
  L.foot = foot_loss(model, final_pose, t.contacts, t.valid);
  L.refine_total = kRefinePos * L.refine_pos + kRefineTraj * L.refine_traj + kContact * L.contact + kFoot * L.foot;
  L.total = L.keyframe_total + L.refine_total;
  return L;
}

}  // namespace mf::training
