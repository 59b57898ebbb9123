#include "prior/runtime/two_stage_runtime.h"

#include <utility>

#include "prior/runtime/inbetween_inputs.h"

namespace mf::runtime {

namespace {

// TwoStageNetImpl::kGateScale.
constexpr float kGateScale = 10.0f;

int pose_inputs(const RigInfo& rig) { return rig.num_joints() * 7 + 4; }

}  // namespace

TwoStageRuntime::TwoStageRuntime(const TwoStageConfig& config, const RigInfo& rig,
                                 InbetweenNormalisation normalisation, WeightReader& w)
    : InbetweenerRuntime(rig, std::move(normalisation)),
      config_(config),
      context_(w, "context", config.trunk(), pose_inputs(rig), rig.num_joints() * 6 + 3, true),
      detail_(w, "detail", config.trunk(), pose_inputs(rig), rig.num_joints() * 6 + 3 + rig.num_feet(), false) {
  if (config.interp_input) gate_ = w.vector("context.gate", 1)[0];
}

void TwoStageRuntime::forward(const InbetweenWindow& in, InbetweenResult* out) const {
  const int T = checked_frames(in, config_.window, "twostage");
  const int J = rig().num_joints(), D = pose_size();
  const InbetweenNormalisation& n = normalisation();
  const MaskedWindow m = masked_window(in, n, J);
  MatrixRXf x = masked_pose_input(in, m, n, J);
  if (config_.interp_input) {
    for (int j = 0; j < J; ++j) x.middleCols(6 * j, 6) = interpolate_known(m.normalised.middleCols(6 * j, 6), flags_of(m.known.col(j)));
  }
  const MatrixRXf offsets = offset_features(T, config_.window);
  MatrixRXf context_out, detail_out;
  context_.forward(concat_columns(x, m.known), key_features(m.key, config_.window), additive_mask(m.key), offsets,
                   &context_out);
  if (config_.interp_input) context_out = x + (kGateScale * gate_) * context_out;
  const MatrixRXf mixed = where_known(m.channel_known, x, context_out);
  detail_.forward(concat_columns(mixed, m.known), MatrixRXf(), additive_mask(m.valid), offsets, &detail_out);
  out->stages = {denormalised(context_out, n), denormalised(mixed + detail_out.leftCols(D), n)};
  out->contact_logits = detail_out.rightCols(rig().num_feet());
  out->keyframe_poses.resize(0, 0);
  out->keyframe_logits.resize(0);
  out->keyframes.resize(0);
}

}  // namespace mf::runtime
