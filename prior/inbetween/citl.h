// CITL, Continuous Intermediate Token Learning (Mo, Hu, Long, Wang; CVPR 2023),
// an InbetweenModel of kind kCitlKind ("citl") with one output stage, "citl".
//
// Architecture (all transformers pre-norm with RMSNorm and GELU feed-forwards):
//   - Sequence-level re-centring (Seq-RC): the mean known root position over the
//     window's known frames (x, y and z) is subtracted from the root positions
//     before normalisation and added back at the output; the root position
//     channels are then divided by stats().pose_std (their stats().pose_mean is
//     not used: re-centring takes its place). Rotation channels are z-scored
//     with stats().
//   - Keyframe tokens: every valid frame with at least one known value. Input =
//     normalised pose times the known mask (per channel) concatenated with the
//     known mask [J + 1] (partial keys), projected to width - time_dim and
//     concatenated with a sinusoidal time embedding (time_dim) of the frame index.
//   - Stage I (keyframe encoder): `layers` self-attention layers over the
//     keyframe tokens only.
//   - Stage II (intermediate tokens): for every frame, a query made from the
//     time embedding of that frame cross-attends (`layers` layers) to the
//     keyframe tokens only.
//   - Stage III (synthesis): tokens in time order (keyframes use their Stage I
//     token after a feed-forward, other frames their intermediate token),
//     Conv1d(k=3) -> `layers` self-attention layers -> Conv1d(k=3) -> D values.
//   - Known values are copied from the input into the output (as in the paper,
//     keyframes are overwritten by the inputs), so the output is exact on them.
// Keys can be any set of frames (at least the first frame in practice), with
// full or partial poses; padding frames (valid = 0) never influence valid frames.
// No contact head: InbetweenOutput::contact_logits is left undefined.
//
// Hyperparameters (defaults: the size the pilots chose for two hours of training
// at 1 CPU thread, docs/MODEL_CARD.md; a few milliseconds per 128-frame window):
//   "width" 64, "layers" 2 (per stage), "heads" 4 (must divide width),
//   "ffn" 256, "time_dim" 16 (even, < width), "window" 128, "fps" 30.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "prior/inbetween/inbetweener.h"

namespace mf {

/// A freshly initialised CITL model. Missing hyperparameters take the
/// defaults above; unknown keys or invalid values throw mf::InputError.
std::unique_ptr<InbetweenModel> make_citl(const std::map<std::string, double>& hyperparameters, const RigInfo& rig);

/// The parameters make_citl would allocate, counted without building it.
int64_t citl_parameter_count(const std::map<std::string, double>& hyperparameters, const RigInfo& rig);

/// The kind's network (find_inbetween_network()): make_citl and its parameter count.
InbetweenNetwork citl_network();

}  // namespace mf
