// CITL (prior/inbetween/citl.h) on Eigen, forward only. Made by
// inbetweener_runtime_from_bytes (inbetween_runtime.h), whose conventions it
// follows: one stage, "citl" (raw poses [T, D], exact on the known values);
// no contact logits.
#pragma once

#include <string>
#include <vector>

#include "prior/inbetween/inbetween_config.h"
#include "prior/runtime/inbetween_runtime.h"
#include "prior/runtime/weight_reader.h"

namespace mf::runtime {

class CitlRuntime final : public InbetweenerRuntime {
 public:
  /// Takes the network's weights out of `w`.
  CitlRuntime(const CitlConfig& config, const RigInfo& rig, InbetweenNormalisation normalisation, WeightReader& w);
  ~CitlRuntime() override;

  std::string kind() const override { return kCitlKind; }
  std::vector<std::string> stage_names() const override { return {"citl"}; }
  int window() const override { return config_.window; }
  double fps() const override { return config_.fps; }
  void forward(const InbetweenWindow& in, InbetweenResult* out) const override;

 private:
  struct Network;
  CitlConfig config_;
  std::unique_ptr<const Network> net_;
};

}  // namespace mf::runtime
