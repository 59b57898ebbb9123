// KeyframeNet + RefineNet: long transitions by keyframe prediction, conditioned
// on a ground trajectory (REFERENCE.md section 4; issue 15). An InbetweenModel
// of kind kKeyframeKind ("keyframe") with two output stages:
//   "keyframe" (stage 0)  the picked keyframes interpolated (SLERP of the joint
//                         rotations, linear root position)
//   "refine"   (stage 1)  RefineNet's answer, the model's output
// and foot contact logits (RefineNet's contact head).
//
// Inputs per frame (every valid frame): the pose features z-scored with
// stats() times the known mask (each joint's 6 channels use its own flag; the
// root position of frames without one is interpolated between the known ones,
// as in two_stage.h), the known mask [J + 1], and the trajectory [4]: ground x,
// z (z-scored with the root position's x and z statistics) and the facing unit
// vector (forward_x, forward_z) (InbetweenBatch::trajectory, canonical frame).
// Without a trajectory (InbetweenBatch::trajectory undefined) the model makes
// one: ground x, z linearly interpolated between the frames whose root position
// is known, the facing direction linearly interpolated between the frames whose
// root rotation (joint 0) is known and normalised (held before the first and
// after the last such frame; where the interpolation cancels out, e.g. halfway
// between opposite facings, the previous known facing).
//
// KeyframeNet: the temporal MLP encoder (blocks::Mlp) of the inputs plus a
// frame-position encoding (an MLP of the distances to the previous and the next
// key frame, i.e. to the last context frame and to the target in a gap, and the
// fraction of the way, blocks::key_features), `layers` pre-LayerNorm transformer
// layers with a learned relative position bias (blocks::Layer), attention over
// every valid frame (no keyframe mask; padding is masked out), an MLP decoder
// to a pose [D] (keyframe_poses) and a keyframe score logit per frame.
//
// Keyframe selection (select_keyframes() below; no gradient): between
// consecutive anchors (frames with a known value, the first and the last valid
// frame) keyframes are picked greedily: from the last pick p, the highest score
// among the frames p + min_spacing .. min(p + max_spacing, next anchor -
// min_spacing) (ties: the later frame). A pick is forced while the next anchor is more than
// max_spacing frames away; closer, the best frame is picked only when its score
// is above 0.5 (sigmoid of the logit). Spacings are therefore within
// [min_spacing, max_spacing] except where two anchors are closer than that.
// The keyframes' poses are KeyframeNet's (detached, so RefineNet's loss does
// not train KeyframeNet); when the batch has a trajectory, their root is moved
// onto it (ground x, z set to the trajectory's, the root rotation turned about
// +Y to its facing: the trajectory is a constraint, like a known value); known
// channels are written over them; they are interpolated
// (interpolate_keyframes()): stage 0.
//
// RefineNet: the same trunk without the frame-position encoding, input = the
// interpolated motion (normalised), the known mask, the trajectory and the
// keyframe flag; output = a residual added to the interpolated motion (stage 1,
// its last layer starts at 0.1x so RefineNet starts near the identity) and foot
// contact logits [B, T, F] for rig().foot_joints.
// Neither stage copies known values into its output except through the
// interpolation (stage 0 is exact on the anchors). Padding frames (valid = 0)
// never influence valid frames.
//
// Parameter names: "keyframe.input.fc1.weight", "keyframe.layers.0.attn.q.weight",
// "refine.output.fc2.bias", ...
//
// Hyperparameters (defaults chosen for 30 fps windows of 10 context frames, up
// to 180-frame transitions and a target; docs/MODEL_CARD.md):
//   "width" 64, "layers" 2 (per network), "heads" 4 (must divide width),
//   "ffn" 128, "window" 256 (maximum frames), "fps" 30,
//   "min_spacing" 5, "max_spacing" 30 (frames between picked keyframes;
//   max_spacing >= 2 * min_spacing).
#pragma once

#include <ATen/core/Tensor.h>

#include <map>
#include <memory>
#include <string>

#include "prior/inbetween/inbetweener.h"

namespace mf {

/// A freshly initialised KeyframeNet + RefineNet. Missing hyperparameters take
/// the defaults above; unknown keys or invalid values throw mf::InputError.
std::unique_ptr<InbetweenModel> make_keyframe_net(const std::map<std::string, double>& hyperparameters,
                                                  const RigInfo& rig);

/// The parameters make_keyframe_net would allocate, counted without building it.
int64_t keyframe_net_parameter_count(const std::map<std::string, double>& hyperparameters, const RigInfo& rig);

/// The kind's network (find_inbetween_network()): make_keyframe_net and its parameter count.
InbetweenNetwork keyframe_net_network();

/// Adaptive keyframe selection (see the top of this file): logits [B, T] (the
/// score logits), anchors [B, T] (bool: frames interpolation must go through),
/// valid [B, T] (float or bool); returns the picked frames [B, T] (bool, never
/// an anchor, never a padding frame). Requires 1 <= min_spacing and
/// 2 * min_spacing <= max_spacing (mf::InputError otherwise).
at::Tensor select_keyframes(const at::Tensor& logits, const at::Tensor& anchors, const at::Tensor& valid,
                            int min_spacing, int max_spacing);

/// Poses [B, T, J * 6 + 3] (raw pose features) interpolated between the frames
/// where `keys` [B, T] (bool) holds: joint rotations by shortest-path SLERP,
/// root positions linearly; frames before the first key and after the last
/// hold the nearest key. Exact at the keys; differentiable in the keys' poses.
at::Tensor interpolate_keyframes(const at::Tensor& poses, const at::Tensor& keys, int num_joints);

/// Trajectory rows [B, T, 4] (x, z, forward_x, forward_z) completed: ground
/// x, z linearly interpolated between the frames where `xz_known` [B, T] (bool)
/// holds, the facing direction between those where `facing_known` holds, then
/// normalised (where that cancels out: the previous known facing, the next one
/// before the first, +z without any); held before the first and after the last
/// known frame. Known rows come back unchanged (facing normalised).
at::Tensor interpolate_trajectory_rows(const at::Tensor& rows, const at::Tensor& xz_known,
                                       const at::Tensor& facing_known);

/// The trajectory the model uses when none is given (see the top of this
/// file): [B, T, 4] from raw poses [B, T, D] and known [B, T, J + 1].
at::Tensor interpolated_trajectory(const at::Tensor& pose, const at::Tensor& known, const RigInfo& rig);

}  // namespace mf
