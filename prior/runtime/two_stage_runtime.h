// The two-stage transformer (prior/inbetween/two_stage.h: Context
// Transformer + Detail Transformer, with or without "interp_input") on
// Eigen, forward only. Made by inbetweener_runtime_from_bytes
// (inbetween_runtime.h), whose conventions it follows: stages "context" and
// "detail" (raw poses [T, D]) and the detail stage's foot contact logits [T, F].
#pragma once

#include <string>
#include <vector>

#include "prior/inbetween/inbetween_config.h"
#include "prior/runtime/inbetween_runtime.h"
#include "prior/runtime/transformer_blocks.h"

namespace mf::runtime {

class TwoStageRuntime final : public InbetweenerRuntime {
 public:
  /// Takes the network's weights ("context.*", "detail.*") out of `w`.
  TwoStageRuntime(const TwoStageConfig& config, const RigInfo& rig, InbetweenNormalisation normalisation,
                  WeightReader& w);

  std::string kind() const override { return kTwoStageKind; }
  std::vector<std::string> stage_names() const override { return {"context", "detail"}; }
  int window() const override { return config_.window; }
  double fps() const override { return config_.fps; }
  void forward(const InbetweenWindow& in, InbetweenResult* out) const override;

 private:
  TwoStageConfig config_;
  TransformerStage context_, detail_;
  float gate_ = 0.0f;  // interp_input: "context.gate" (the correction's scale / 10)
};

}  // namespace mf::runtime
