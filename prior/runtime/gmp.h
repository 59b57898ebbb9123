// The NeMF global motion predictor (GMP) on Eigen, with the gradient with
// respect to its inputs written out (prior/model/nemf.h describes the network;
// FrozenGmpFunction in nemf.cc is the libtorch node this reproduces): temporal
// convolutions over one window's per-frame pose features (replication-padded,
// leaky ReLU 0.2, residual blocks) and a per-frame output layer.
#pragma once

#include <string>
#include <vector>

#include "prior/model/nemf_config.h"
#include "prior/runtime/tensor_ops.h"
#include "prior/runtime/weight_reader.h"

namespace mf::runtime {

/// What a GMP evaluation keeps for its input gradient, and the gradient's
/// scratch; reused across evaluations it allocates nothing after the first
/// of a given length. One workspace per thread.
struct GmpWorkspace {
  MatrixRXf x, g_y;               ///< NemfRuntime's normalised inputs and output gradient
  std::vector<MatrixRXf> padded;  ///< per padded convolution: its input, replication-padded [T + 2R, C]
  std::vector<MatrixRXf> pre;     ///< per padded convolution: its output before the leaky ReLU [T, W]
  MatrixRXf h, activated, g_h, g_padded, g_in;
};

/// One GMP's network (the default "gmp" or the "steering_gmp"), on inputs
/// already normalised with the GMP statistics; NemfRuntime adds them.
class NemfGmpNetwork {
 public:
  /// Takes the weights "<prefix>.*" for `config`, `joints` and `feet`.
  NemfGmpNetwork(const NemfConfig& config, int joints, int feet, const std::string& prefix, WeightReader& weights);

  /// x [T, J * 3 + 6] (normalised) -> y [T, 4 + F] (normalised velocity and
  /// height, contact logits); y resized. T >= 1.
  void forward(ConstMatrixRef x, GmpWorkspace* ws, MatrixRXf* y) const;

  /// The input gradient g_x [T, J * 3 + 6] (resized) from g_y [T, 4 + F] at
  /// the last forward() in `ws`.
  void input_gradient(GmpWorkspace* ws, ConstMatrixRef g_y, MatrixRXf* g_x) const;

 private:
  int pad_;
  std::vector<Conv1dWeights> convs_;  // the input convolution, then the blocks
  Conv1dWeights output_;
};

}  // namespace mf::runtime
