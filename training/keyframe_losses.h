// Training losses of KeyframeNet + RefineNet (prior/inbetween/keyframe_net.h),
// weights of REFERENCE.md section 4:
//   KeyframeNet: pos 1.0 (inbetween_pose_loss of keyframe_poses: rotations,
//     FK positions, root), traj 0.5 (L1 of trajectory_features() of
//     keyframe_poses against the ground truth's: ground x, z in metres and the
//     facing vector), score 1.0 (binary cross-entropy of the score logits
//     against the Salient Poses scores of training/salient_poses.h, on the
//     frames strictly inside the transition), smooth 0.1 (L1 of the difference
//     between predicted and true frame-to-frame changes of the normalised pose,
//     which penalises jitter without pulling towards a still pose).
//   RefineNet: pos 2.0 (inbetween_pose_loss of the last stage), traj 0.2,
//     contact 0.05 (BCE of the contact logits against gmp_targets contacts),
//     foot 0.05 (mean speed, metres per frame, of the foot joints of the output
//     on the frames where the ground truth's foot is in contact).
// All terms are means over the valid frames.
#pragma once

#include <ATen/core/Tensor.h>

#include "prior/inbetween/inbetweener.h"

namespace mf::training {

struct KeyframeTargets {
  at::Tensor pose;        ///< [B, T, D] raw ground truth
  at::Tensor valid;       ///< [B, T]
  at::Tensor trajectory;  ///< [B, T, 4] the ground truth's (trajectory_features())
  at::Tensor scores;      ///< [B, T] Salient Poses scores in [0, 1]
  at::Tensor score_mask;  ///< [B, T] 1 on the frames the score loss covers
  at::Tensor contacts;    ///< [B, T, F] 0/1, or undefined
};

struct KeyframeLosses {
  at::Tensor keyframe_pos, keyframe_traj, score, smooth;  ///< KeyframeNet's terms
  at::Tensor refine_pos, refine_traj, contact, foot;      ///< RefineNet's terms
  at::Tensor keyframe_total, refine_total, total;         ///< weighted sums
  InbetweenLossParts refine_parts;                        ///< of refine_pos
};

/// The losses of one forward pass of a keyframe model (`out` must hold
/// keyframe_poses and keyframe_logits; InputError otherwise).
KeyframeLosses keyframe_losses(const InbetweenModel& model, const InbetweenOutput& out, const KeyframeTargets& t);

/// L1 distance of the trajectory features of raw poses [B, T, D] to `trajectory`
/// [B, T, 4], averaged over the 4 values and the valid frames.
at::Tensor trajectory_l1(const InbetweenModel& model, const at::Tensor& pose, const at::Tensor& trajectory,
                         const at::Tensor& valid);

}  // namespace mf::training
