// Two-stage Transformer in-betweener (Qin, Zheng, Zhou; SIGGRAPH Asia 2022), an
// InbetweenModel of kind kTwoStageKind ("twostage") with two output stages,
// "context" (stage 0) and "detail" (stage 1), and foot contact logits.
//
// Input per frame: the pose features z-scored with stats(), times the known
// mask (each joint's 6 channels use its own flag), concatenated with the known
// mask [J + 1]. The root-position channels are never zero: frames whose root
// position is unknown get the linear interpolation between the nearest frames
// before and after whose root position is known (held constant before the first
// and after the last such frame).
//
// Both stages share one trunk: an MLP encoder (PReLU) to `width`, `layers`
// pre-LayerNorm transformer layers (multi-head attention, ReLU feed-forward of
// `ffn` units, no dropout) and an MLP decoder. Attention scores carry a learned
// relative position bias per head (Transformer-XL style relative encoding, in
// its cheap scalar form): an MLP (per layer) of the signed frame offset j - i
// (sinusoids of the offset and offset / window, clamped to the window) added
// to the scores of every query i and key j.
//   - Context Transformer: a keyframe positional encoding is added to the
//     encoded input: an MLP of (distance to the previous key frame, distance
//     to the next key frame, both clamped to the window and encoded like the
//     offsets above, and the fraction of the way between them), a key frame
//     being a valid frame with at least one known value (this generalises the
//     paper's "last context frame and target" to arbitrary key sets). Every query attends only to key
//     frames. Its output (D values per frame) is the whole pose: stage 0.
//   - Detail Transformer: no keyframe encoding, attention over all valid
//     frames. Input: the context output (normalised) with the known values
//     written over it, concatenated with the known mask. Output: a correction
//     added to that input (stage 1) and foot contact logits [B, T, F] for
//     rig().foot_joints.
// With "interp_input" 1 (a design after SILK and the Delta-interpolator,
// ../shared/docs/REFERENCE.md section 8), the rotation channels of unknown
// frames are not zero but, per joint, the linear interpolation of its 6D
// between its nearest known frames (as the root's), and the Context
// Transformer's output is a correction added to that input, scaled by a
// learned gate (10 x the parameter "context.gate", which starts at 0): a new model starts at
// interpolation refined by the detail stage. Files without the key are of the
// original design.
// Neither stage copies known values into its output (callers overwrite known
// frames if they want them exact). Padding frames (valid = 0) never influence
// valid frames, unless a window has no known value at all (every attention row
// of the context stage is then fully masked and attends uniformly).
//
// Parameter names are stable: "context.input.fc1.weight",
// "context.layers.0.attn.q.weight", "detail.output.fc2.bias", ...
//
// Hyperparameters (defaults: the size the pilots chose for two hours of training
// at 1 CPU thread, docs/MODEL_CARD.md; a few milliseconds per 128-frame window):
//   "width" 64 (d_model), "layers" 2 (per stage), "heads" 4 (must divide
//   width), "ffn" 128, "window" 128 (maximum frames), "fps" 30, "interp_input" 0.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "prior/inbetween/inbetweener.h"

namespace mf {

/// A freshly initialised two-stage model. Missing hyperparameters take the
/// defaults above; unknown keys or invalid values throw mf::InputError.
std::unique_ptr<InbetweenModel> make_two_stage(const std::map<std::string, double>& hyperparameters, const RigInfo& rig);

/// The parameters make_two_stage would allocate, counted without building it.
int64_t two_stage_parameter_count(const std::map<std::string, double>& hyperparameters, const RigInfo& rig);

/// The kind's network (find_inbetween_network()): make_two_stage and its parameter count.
InbetweenNetwork two_stage_network();

}  // namespace mf
