// Building blocks shared by the transformer in-betweeners (two_stage.cc,
// keyframe_net.cc): the MLP encoder, pre-LayerNorm transformer layers whose
// attention carries a learned relative position bias, the keyframe (frame
// position) encoding and the root interpolation of the inputs. Internal to
// prior/inbetween/ (not part of the product's API). Parameter names of the
// modules are stable: they are the keys of the model files ("input.fc1.weight",
// "layers.0.attn.q.weight", "layers.0.attn.relative.fc2.bias", ...).
#pragma once

#include <ATen/core/Tensor.h>
#include <torch/nn/module.h>
#include <torch/nn/modules/activation.h>
#include <torch/nn/modules/container/modulelist.h>
#include <torch/nn/modules/linear.h>
#include <torch/nn/modules/normalization.h>

#include <cstdint>
#include <vector>

#include "prior/inbetween/transformer_sizes.h"

namespace mf::blocks {

/// Linear -> PReLU -> Linear.
struct MlpImpl : torch::nn::Module {
  MlpImpl(int in, int hidden, int out);
  at::Tensor forward(const at::Tensor& x);
  torch::nn::Linear fc1{nullptr}, fc2{nullptr};
  torch::nn::PReLU act{nullptr};
};
TORCH_MODULE(Mlp);

/// Linear -> ReLU -> Linear back to `width`.
struct FeedForwardImpl : torch::nn::Module {
  FeedForwardImpl(int width, int hidden);
  at::Tensor forward(const at::Tensor& x);
  torch::nn::Linear fc1{nullptr}, fc2{nullptr};
};
TORCH_MODULE(FeedForward);

/// Geometry of one forward pass, shared by every layer of a trunk.
struct Positions {
  at::Tensor offsets;         ///< [2T - 1, kDistanceFeatures] of the key - query offsets -(T-1)..T-1
  at::Tensor relative_index;  ///< [T, T] long: offset index of (query i, key j)
};

/// Frame distances [...] (float, frames) -> [..., kDistanceFeatures].
at::Tensor distance_features(const at::Tensor& frames, int window);
/// The offsets of a T-frame pass (clamped to +-(window - 1)).
Positions make_positions(int64_t T, int window, const at::TensorOptions& options);

/// Multi-head self-attention with a learned relative position bias per head:
/// scores = q . k / sqrt(dh) + b_h(j - i) + mask, b = MLP of the offset features.
struct AttentionImpl : torch::nn::Module {
  AttentionImpl(int width, int heads);
  /// x [B, T, W]; mask [B, 1, 1, T] (or [B, 1, T, T]) additive.
  at::Tensor forward(const at::Tensor& x, const at::Tensor& mask, const Positions& pos);
  int64_t heads_, head_size_;
  torch::nn::Linear q{nullptr}, k{nullptr}, v{nullptr}, out{nullptr};
  Mlp relative{nullptr};
};
TORCH_MODULE(Attention);

/// Pre-LayerNorm transformer layer: x + attn(norm(x)), then x + ffn(norm(x)).
struct LayerImpl : torch::nn::Module {
  explicit LayerImpl(const TrunkSize& size);
  at::Tensor forward(at::Tensor x, const at::Tensor& mask, const Positions& pos);
  torch::nn::LayerNorm norm1{nullptr}, norm2{nullptr};
  Attention attn{nullptr};
  FeedForward ffn{nullptr};
};
TORCH_MODULE(Layer);

/// One transformer: input MLP, optional keyframe encoding (an MLP of
/// key_features() added to the encoded input), pre-norm layers, final norm,
/// output MLP. Modules "input", "keyframe" (when enabled), "layers", "norm",
/// "output".
struct StageImpl : torch::nn::Module {
  StageImpl(const TrunkSize& size, int inputs, int outputs, bool keyframe_encoding);
  /// key_features may be undefined without the keyframe encoding.
  at::Tensor forward(const at::Tensor& x, const at::Tensor& key_features, const at::Tensor& mask,
                     const Positions& pos);
  Mlp input{nullptr}, keyframe{nullptr}, output{nullptr};
  torch::nn::ModuleList layer_list{nullptr};
  std::vector<Layer> layers;
  torch::nn::LayerNorm norm{nullptr};
};
TORCH_MODULE(Stage);

/// The parameters a Stage(size, inputs, outputs, keyframe_encoding) holds,
/// counted without building it (model files are checked against this before a
/// network is allocated; tests compare it with the built module's count).
int64_t stage_parameter_count(const TrunkSize& size, int inputs, int outputs, bool keyframe_encoding);

/// Index of the last frame at or before t where `flag` holds ([B, T] bool ->
/// [B, T] long), `none` where there is none. With `forward` false: the first
/// at or after.
at::Tensor nearest_flagged(const at::Tensor& flag, bool forward, int64_t none);

/// Keyframe encoding inputs [B, T, kKeyFeatures] from key [B, T] (bool):
/// distance to the previous and to the next key (clamped to `window`, as
/// distance_features()) and the fraction of the way between them.
at::Tensor key_features(const at::Tensor& key, int window);

/// Values [B, T, C] linearly interpolated between the frames where `known`
/// [B, T] (bool) holds, held before the first and after the last (zero when a
/// row has none).
at::Tensor interpolate_known(const at::Tensor& values, const at::Tensor& known);

/// Additive key mask [B, 1, 1, T]: 0 where `keep` [B, T] (bool), kMasked elsewhere.
at::Tensor additive_mask(const at::Tensor& keep, const at::TensorOptions& options);

}  // namespace mf::blocks
