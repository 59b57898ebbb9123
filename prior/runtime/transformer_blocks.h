// The transformer in-betweeners' building blocks (prior/inbetween/transformer_blocks.h)
// on Eigen, forward only, for one window (row-major [T, C], one row per
// frame): the PReLU MLP, the ReLU feed-forward, multi-head self-attention with
// the learned relative position bias, the pre-LayerNorm layer, the stage
// (trunk) the two-stage transformer and KeyframeNet + RefineNet are made of,
// and the geometry of a pass (offset features, key features, interpolation
// between known frames). Weights are read by the libtorch modules' parameter
// names under a prefix ("context.layers.0.attn.q.weight"). Internal to
// prior/runtime/ (the in-betweeners' public header is inbetween_runtime.h).
#pragma once

#include <string>
#include <vector>

#include "prior/inbetween/transformer_sizes.h"
#include "prior/runtime/tensor_ops.h"
#include "prior/runtime/weight_reader.h"

namespace mf::runtime {

/// y [rows, out] = x W^T + b: libtorch's Linear on the rows of x (a kernel-1
/// conv1d of WeightReader::linear's weights). `y` is resized.
void linear_rows(ConstMatrixRef x, const Conv1dWeights& w, MatrixRXf* y);

/// In place, the softmax of every row (the row's maximum subtracted first).
void softmax_rows(MatrixRef x);

/// Linear -> PReLU (one slope) -> Linear: modules fc1, act, fc2.
class PreluMlp {
 public:
  PreluMlp(WeightReader& w, const std::string& prefix, int in, int hidden, int out);
  /// y [rows, out] (resized) of x [rows, in].
  void forward(ConstMatrixRef x, MatrixRXf* y) const;

 private:
  Conv1dWeights fc1_, fc2_;
  float slope_;
};

/// Linear -> ReLU -> Linear back to the width: modules fc1, fc2.
class ReluFeedForward {
 public:
  ReluFeedForward(WeightReader& w, const std::string& prefix, int width, int hidden);
  void forward(ConstMatrixRef x, MatrixRXf* y) const;

 private:
  Conv1dWeights fc1_, fc2_;
};

/// libtorch's LayerNorm over the last dimension (eps 1e-5): weight, bias.
class LayerNorm {
 public:
  LayerNorm(WeightReader& w, const std::string& prefix, int width);
  void forward(ConstMatrixRef x, MatrixRXf* y) const;

 private:
  RowVectorXf gamma_, beta_;
};

/// Frame distances [n] -> [n, kDistanceFeatures]: sinusoids of kFrequencies
/// frequencies and the distance / window (blocks::distance_features).
MatrixRXf distance_features(const Eigen::Ref<const Eigen::VectorXf>& frames, int window);

/// The offset features of a T-frame pass: row o is the key - query offset
/// o - (T - 1), clamped to +-(window - 1) (blocks::make_positions).
MatrixRXf offset_features(int T, int window);

/// Keyframe encoding inputs [T, kKeyFeatures] from key [T] (blocks::key_features).
MatrixRXf key_features(const std::vector<bool>& key, int window);

/// Values [T, C] linearly interpolated between the rows where `known` holds,
/// held before the first and after the last, zero without any
/// (blocks::interpolate_known).
MatrixRXf interpolate_known(ConstMatrixRef values, const std::vector<bool>& known);

/// Additive key mask [T]: 0 where `keep`, blocks::kMasked elsewhere.
RowVectorXf additive_mask(const std::vector<bool>& keep);

/// Scaled dot-product attention of every head (columns h * dh .. of q, k,
/// v; q already scaled by 1 / sqrt(dh)): o [Tq, W] (resized). Scores get,
/// per key j, key_mask[j] [Tk] added, and with a relative bias [2 Tk - 1, H]
/// (self-attention, Tq = Tk) first bias(j - i + Tk - 1, h) + key_mask[j].
/// Keys masked with blocks::kMasked are left out (their weight is 0) unless
/// every key is masked, when all are attended (uniformly, as in libtorch).
void attend_heads(ConstMatrixRef q, ConstMatrixRef k, ConstMatrixRef v, int heads, const MatrixRXf* relative_bias,
                  const RowVectorXf& key_mask, MatrixRXf* o);

/// Multi-head self-attention with a learned relative position bias per head
/// (blocks::Attention): modules q, k, v, out and the offset MLP "relative".
class RelativeAttention {
 public:
  RelativeAttention(WeightReader& w, const std::string& prefix, int width, int heads);
  /// x [T, W] -> y [T, W]; key_mask [T] additive, offsets = offset_features(T).
  void forward(ConstMatrixRef x, const RowVectorXf& key_mask, ConstMatrixRef offsets, MatrixRXf* y) const;

 private:
  int heads_, head_size_;
  Conv1dWeights q_, k_, v_, out_;
  PreluMlp relative_;
};

/// Pre-LayerNorm layer: x + attn(norm1(x)), then x + ffn(norm2(x)).
class TransformerLayer {
 public:
  TransformerLayer(WeightReader& w, const std::string& prefix, const blocks::TrunkSize& size);
  /// In place on x [T, W].
  void forward(MatrixRXf* x, const RowVectorXf& key_mask, ConstMatrixRef offsets) const;

 private:
  LayerNorm norm1_, norm2_;
  RelativeAttention attn_;
  ReluFeedForward ffn_;
};

/// One transformer (blocks::Stage): input MLP, optional keyframe encoding,
/// layers, final LayerNorm, output MLP, under `prefix` ("context").
class TransformerStage {
 public:
  TransformerStage(WeightReader& w, const std::string& prefix, const blocks::TrunkSize& size, int inputs, int outputs,
                   bool keyframe_encoding);
  /// x [T, inputs] -> y [T, outputs]; key_features [T, kKeyFeatures] (ignored
  /// without the keyframe encoding), key_mask [T] additive, offsets as above.
  void forward(ConstMatrixRef x, ConstMatrixRef key_features, const RowVectorXf& key_mask, ConstMatrixRef offsets,
               MatrixRXf* y) const;

 private:
  PreluMlp input_;
  std::vector<PreluMlp> keyframe_;  // one or none
  std::vector<TransformerLayer> layers_;
  LayerNorm norm_;
  PreluMlp output_;
};

}  // namespace mf::runtime
