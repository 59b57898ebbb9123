#include "prior/inbetween/transformer_blocks.h"

#include <ATen/ATen.h>

#include <cmath>

namespace mf::blocks {

MlpImpl::MlpImpl(int in, int hidden, int out) {
  fc1 = register_module("fc1", torch::nn::Linear(in, hidden));
  act = register_module("act", torch::nn::PReLU());
  fc2 = register_module("fc2", torch::nn::Linear(hidden, out));
}

at::Tensor MlpImpl::forward(const at::Tensor& x) { return fc2->forward(act->forward(fc1->forward(x))); }

FeedForwardImpl::FeedForwardImpl(int width, int hidden) {
  fc1 = register_module("fc1", torch::nn::Linear(width, hidden));
  fc2 = register_module("fc2", torch::nn::Linear(hidden, width));
}

at::Tensor FeedForwardImpl::forward(const at::Tensor& x) { return fc2->forward(at::relu(fc1->forward(x))); }

namespace {

int64_t linear_count(int64_t in, int64_t out) { return in * out + out; }
// Linear, PReLU (one slope), Linear.
int64_t mlp_count(int64_t in, int64_t hidden, int64_t out) { return linear_count(in, hidden) + 1 + linear_count(hidden, out); }
int64_t layer_norm_count(int64_t width) { return 2 * width; }

}  // namespace

int64_t stage_parameter_count(const TrunkSize& c, int inputs, int outputs, bool keyframe_encoding) {
  const int64_t w = c.width;
  const int64_t attention = 4 * linear_count(w, w) + mlp_count(kDistanceFeatures, kRelativeHidden, c.heads);
  const int64_t layer = 2 * layer_norm_count(w) + attention + linear_count(w, c.ffn) + linear_count(c.ffn, w);
  return mlp_count(inputs, w, w) + (keyframe_encoding ? mlp_count(kKeyFeatures, w, w) : 0) + c.layers * layer +
         layer_norm_count(w) + mlp_count(w, w, outputs);
}

at::Tensor distance_features(const at::Tensor& frames, int window) {
  at::Tensor i = at::arange(kFrequencies, frames.options());
  const double ratio = std::log(2.0 * window / 4.0) / (kFrequencies - 1);
  at::Tensor omega = (2.0 * M_PI / 4.0) * at::exp(i * -ratio);
  at::Tensor angle = frames.unsqueeze(-1) * omega;
  return at::cat({at::sin(angle), at::cos(angle), frames.unsqueeze(-1) / window}, -1);
}

Positions make_positions(int64_t T, int window, const at::TensorOptions& options) {
  Positions p;
  const double limit = window - 1;
  p.offsets = distance_features(at::arange(-(T - 1), T, options).clamp(-limit, limit), window);
  at::Tensor t = at::arange(T, at::kLong);
  p.relative_index = t.unsqueeze(0) - t.unsqueeze(1) + (T - 1);
  return p;
}

AttentionImpl::AttentionImpl(int width, int heads) : heads_(heads), head_size_(width / heads) {
  q = register_module("q", torch::nn::Linear(width, width));
  k = register_module("k", torch::nn::Linear(width, width));
  v = register_module("v", torch::nn::Linear(width, width));
  out = register_module("out", torch::nn::Linear(width, width));
  relative = register_module("relative", Mlp(kDistanceFeatures, kRelativeHidden, heads));
}

at::Tensor AttentionImpl::forward(const at::Tensor& x, const at::Tensor& mask, const Positions& pos) {
  const int64_t T = x.size(1);
  auto split_heads = [&](const at::Tensor& t) { return t.unflatten(-1, {heads_, head_size_}).transpose(1, 2); };
  at::Tensor qh = split_heads(q->forward(x) * (1.0 / std::sqrt(static_cast<double>(head_size_))));
  at::Tensor kh = split_heads(k->forward(x));
  at::Tensor vh = split_heads(v->forward(x));
  // [2T - 1, H] -> [H, T, T], shared by the batch
  at::Tensor bias =
      relative->forward(pos.offsets).t().index_select(1, pos.relative_index.flatten()).view({heads_, T, T});
  at::Tensor scores = at::matmul(qh, kh.transpose(-1, -2)) + (bias + mask);
  at::Tensor o = at::matmul(at::softmax(scores, -1), vh);  // [B, H, T, dh]
  return out->forward(o.transpose(1, 2).flatten(2));
}

LayerImpl::LayerImpl(const TrunkSize& c) {
  norm1 = register_module("norm1", torch::nn::LayerNorm(torch::nn::LayerNormOptions({c.width})));
  attn = register_module("attn", Attention(c.width, c.heads));
  norm2 = register_module("norm2", torch::nn::LayerNorm(torch::nn::LayerNormOptions({c.width})));
  ffn = register_module("ffn", FeedForward(c.width, c.ffn));
}

at::Tensor LayerImpl::forward(at::Tensor x, const at::Tensor& mask, const Positions& pos) {
  x = x + attn->forward(norm1->forward(x), mask, pos);
  return x + ffn->forward(norm2->forward(x));
}

StageImpl::StageImpl(const TrunkSize& c, int inputs, int outputs, bool keyframe_encoding) {
  input = register_module("input", Mlp(inputs, c.width, c.width));
  if (keyframe_encoding) keyframe = register_module("keyframe", Mlp(kKeyFeatures, c.width, c.width));
  layer_list = register_module("layers", torch::nn::ModuleList());
  for (int l = 0; l < c.layers; ++l) {
    layers.push_back(Layer(c));
    layer_list->push_back(layers.back());
  }
  norm = register_module("norm", torch::nn::LayerNorm(torch::nn::LayerNormOptions({c.width})));
  output = register_module("output", Mlp(c.width, c.width, outputs));
}

at::Tensor StageImpl::forward(const at::Tensor& x, const at::Tensor& key_features, const at::Tensor& mask,
                              const Positions& pos) {
  at::Tensor h = input->forward(x);
  if (!keyframe.is_empty()) h = h + keyframe->forward(key_features);
  for (auto& layer : layers) h = layer->forward(h, mask, pos);
  return output->forward(norm->forward(h));
}

at::Tensor nearest_flagged(const at::Tensor& flag, bool forward, int64_t none) {
  const int64_t T = flag.size(1);
  at::Tensor t = at::arange(T, at::kLong).unsqueeze(0).expand_as(flag);
  if (forward) return std::get<0>(at::cummax(at::where(flag, t, at::full_like(t, none)), 1));
  at::Tensor reversed = at::where(flag, t, at::full_like(t, none)).flip(1);
  return std::get<0>(at::cummin(reversed, 1)).flip(1);
}

at::Tensor key_features(const at::Tensor& key, int window) {
  const int64_t T = key.size(1);
  const int64_t far = 2 * static_cast<int64_t>(window) + T;
  at::Tensor t = at::arange(T, at::kLong).unsqueeze(0);
  at::Tensor before = (t - nearest_flagged(key, true, -far)).clamp_max(window).to(at::kFloat);
  at::Tensor after = (nearest_flagged(key, false, far) - t).clamp_max(window).to(at::kFloat);
  at::Tensor span = before + after;
  at::Tensor fraction = at::where(span > 0, before / span.clamp_min(1.0), at::zeros_like(span));
  return at::cat({distance_features(before, window), distance_features(after, window), fraction.unsqueeze(-1)}, -1);
}

at::Tensor interpolate_known(const at::Tensor& values, const at::Tensor& known) {
  const int64_t B = values.size(0), T = values.size(1), C = values.size(2);
  at::Tensor prev = nearest_flagged(known, true, -1);
  at::Tensor next = nearest_flagged(known, false, T);
  at::Tensor has_prev = (prev >= 0).unsqueeze(-1), has_next = (next < T).unsqueeze(-1);
  at::Tensor known_only = at::where(known.unsqueeze(-1), values, at::zeros_like(values));
  at::Tensor pv = known_only.gather(1, prev.clamp(0, T - 1).unsqueeze(-1).expand({B, T, C}));
  at::Tensor nv = known_only.gather(1, next.clamp(0, T - 1).unsqueeze(-1).expand({B, T, C}));
  at::Tensor t = at::arange(T, at::kLong).unsqueeze(0);
  at::Tensor w =
      ((t - prev).to(values.scalar_type()) / (next - prev).clamp_min(1).to(values.scalar_type())).unsqueeze(-1);
  at::Tensor both = pv + (nv - pv) * w;
  return at::where(has_prev, at::where(has_next, both, pv), at::where(has_next, nv, at::zeros_like(values)));
}

at::Tensor additive_mask(const at::Tensor& keep, const at::TensorOptions& options) {
  at::Tensor zero = at::zeros({1}, options);
  at::Tensor masked = at::full({1}, kMasked, options);
  return at::where(keep, zero, masked).view({keep.size(0), 1, 1, keep.size(1)});
}

}  // namespace mf::blocks
