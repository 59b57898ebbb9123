// The NeMF encoders on Eigen, forward only (prior/model/nemf.h describes the
// networks; LocalEncoderImpl and GlobalEncoderImpl in nemf.cc): the local
// encoder's skeleton-aware strided convolutions with group normalisation over
// the local-motion features, and the global encoder's strided convolutions
// over the root orientation, each ending in a linear head that gives the mean
// and log-variance of its latent.
#pragma once

#include <vector>

#include "prior/model/nemf_config.h"
#include "prior/runtime/tensor_ops.h"
#include "prior/runtime/weight_reader.h"

namespace mf::runtime {

/// The two encoders of one window; inputs are normalised, masked and
/// zero-padded to the full window by NemfRuntime::encode_features.
class NemfEncoders {
 public:
  /// Takes "local_encoder.*" and "global_encoder.*" for `config` and the
  /// skeleton's `parents` (the skeleton convolutions' joint adjacency).
  NemfEncoders(const NemfConfig& config, const std::vector<int>& parents, WeightReader& weights);

  /// local [window, J * 16] (per joint its 15 features, then the mask) ->
  /// [2 * zl]: mu_l, then logvar_l.
  Eigen::VectorXf local(ConstMatrixRef input) const;
  /// global [window, 7] (root 6D, then the mask) -> [2 * zg]: mu_g, then logvar_g.
  Eigen::VectorXf global(ConstMatrixRef input) const;

 private:
  struct Stage {
    Conv1dWeights conv;
    RowVectorXf norm_weight, norm_bias;  // the local encoder's group norm; empty in the global one
  };
  static Eigen::VectorXf run(const std::vector<Stage>& stages, int groups, const Conv1dWeights* mix,
                             const MatrixRXf& head, const RowVectorXf& head_bias, ConstMatrixRef input);
  int joints_, window_;
  std::vector<Stage> local_, global_;
  Conv1dWeights mix_;
  MatrixRXf local_head_, global_head_;  // [2 z, channels * window / 16], channels-first flattening
  RowVectorXf local_head_bias_, global_head_bias_;
};

}  // namespace mf::runtime
