#include "prior/runtime/transformer_blocks.h"

#include <algorithm>
#include <cmath>

namespace mf::runtime {

namespace {

// libtorch's LayerNorm default.
constexpr float kLayerNormEps = 1e-5f;

// Softmax scores more than 80 below the row's largest count as 0 (their
// terms are below 2e-35 of its): clamped there before the exponential and
// zeroed after it. Eigen's exp of a masked key's score (-1e9) would be a
// denormal (libtorch's is 0), and every product with a denormal costs ~100
// cycles.
constexpr float kLowestScore = -80.0f;
constexpr float kNegligibleTerm = 2e-35f;  // above exp(-80) = 1.8e-35

// Index of the last row at or before t where `flag` holds (`none` without
// one); with `forward` false, the first at or after (blocks::nearest_flagged).
std::vector<int> nearest_flagged(const std::vector<bool>& flag, bool forward, int none) {
  const int T = static_cast<int>(flag.size());
  std::vector<int> out(T, none);
  int last = none;
  for (int i = 0; i < T; ++i) {
    const int t = forward ? i : T - 1 - i;
    if (flag[t]) last = t;
    out[t] = last;
  }
  return out;
}

}  // namespace

void linear_rows(ConstMatrixRef x, const Conv1dWeights& w, MatrixRXf* y) { conv1d(x, w, 1, y); }

void softmax_rows(MatrixRef x) {
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    auto row = x.row(i).array();
    row = (row - row.maxCoeff()).max(kLowestScore).exp();
    float* __restrict v = x.row(i).data();
    for (Eigen::Index j = 0; j < x.cols(); ++j) v[j] = v[j] > kNegligibleTerm ? v[j] : 0.0f;
    row *= 1.0f / row.sum();
  }
}

PreluMlp::PreluMlp(WeightReader& w, const std::string& prefix, int in, int hidden, int out)
    : fc1_(w.linear(prefix + ".fc1", hidden, in)),
      fc2_(w.linear(prefix + ".fc2", out, hidden)),
      slope_(w.vector(prefix + ".act.weight", 1)[0]) {}

void PreluMlp::forward(ConstMatrixRef x, MatrixRXf* y) const {
  MatrixRXf h;
  linear_rows(x, fc1_, &h);
  leaky_relu(h, slope_);
  linear_rows(h, fc2_, y);
}

ReluFeedForward::ReluFeedForward(WeightReader& w, const std::string& prefix, int width, int hidden)
    : fc1_(w.linear(prefix + ".fc1", hidden, width)), fc2_(w.linear(prefix + ".fc2", width, hidden)) {}

void ReluFeedForward::forward(ConstMatrixRef x, MatrixRXf* y) const {
  MatrixRXf h;
  linear_rows(x, fc1_, &h);
  leaky_relu(h, 0.0f);
  linear_rows(h, fc2_, y);
}

LayerNorm::LayerNorm(WeightReader& w, const std::string& prefix, int width)
    : gamma_(w.vector(prefix + ".weight", width)), beta_(w.vector(prefix + ".bias", width)) {}

void LayerNorm::forward(ConstMatrixRef x, MatrixRXf* y) const {
  Eigen::VectorXf mean, rstd;
  layer_norm_rows(x, gamma_, beta_, kLayerNormEps, y, &mean, &rstd);
}

MatrixRXf distance_features(const Eigen::Ref<const Eigen::VectorXf>& frames, int window) {
  using blocks::kFrequencies;
  const float ratio = static_cast<float>(std::log(2.0 * window / 4.0) / (kFrequencies - 1));
  const float base = static_cast<float>(2.0 * M_PI / 4.0), window_f = static_cast<float>(window);
  Eigen::RowVectorXf omega(kFrequencies);
  for (int i = 0; i < kFrequencies; ++i) omega[i] = base * std::exp(static_cast<float>(i) * -ratio);
  MatrixRXf out(frames.size(), blocks::kDistanceFeatures);
  for (Eigen::Index n = 0; n < frames.size(); ++n) {
    for (int i = 0; i < kFrequencies; ++i) {
      const float angle = frames[n] * omega[i];
      out(n, i) = std::sin(angle);
      out(n, kFrequencies + i) = std::cos(angle);
    }
    out(n, 2 * kFrequencies) = frames[n] / window_f;
  }
  return out;
}

MatrixRXf offset_features(int T, int window) {
  const float limit = static_cast<float>(window - 1);
  Eigen::VectorXf offsets(2 * T - 1);
  for (int o = 0; o < 2 * T - 1; ++o) offsets[o] = std::clamp(static_cast<float>(o - (T - 1)), -limit, limit);
  return distance_features(offsets, window);
}

MatrixRXf key_features(const std::vector<bool>& key, int window) {
  const int T = static_cast<int>(key.size()), far = 2 * window + T;
  const std::vector<int> prev = nearest_flagged(key, true, -far), next = nearest_flagged(key, false, far);
  Eigen::VectorXf before(T), after(T), fraction(T);
  for (int t = 0; t < T; ++t) {
    before[t] = static_cast<float>(std::min(t - prev[t], window));
    after[t] = static_cast<float>(std::min(next[t] - t, window));
    const float span = before[t] + after[t];
    fraction[t] = span > 0 ? before[t] / std::max(span, 1.0f) : 0.0f;
  }
  MatrixRXf out(T, blocks::kKeyFeatures);
  out << distance_features(before, window), distance_features(after, window), fraction;
  return out;
}

MatrixRXf interpolate_known(ConstMatrixRef values, const std::vector<bool>& known) {
  const int T = static_cast<int>(values.rows());
  const std::vector<int> prev = nearest_flagged(known, true, -1), next = nearest_flagged(known, false, T);
  MatrixRXf out = MatrixRXf::Zero(T, values.cols());
  for (int t = 0; t < T; ++t) {
    const bool has_prev = prev[t] >= 0, has_next = next[t] < T;
    if (has_prev && has_next) {
      const float w = static_cast<float>(t - prev[t]) / static_cast<float>(std::max(next[t] - prev[t], 1));
      out.row(t) = values.row(prev[t]) + (values.row(next[t]) - values.row(prev[t])) * w;
    } else if (has_prev) {
      out.row(t) = values.row(prev[t]);
    } else if (has_next) {
      out.row(t) = values.row(next[t]);
    }
  }
  return out;
}

RowVectorXf additive_mask(const std::vector<bool>& keep) {
  RowVectorXf m(static_cast<Eigen::Index>(keep.size()));
  for (size_t t = 0; t < keep.size(); ++t) m[t] = keep[t] ? 0.0f : static_cast<float>(blocks::kMasked);
  return m;
}

RelativeAttention::RelativeAttention(WeightReader& w, const std::string& prefix, int width, int heads)
    : heads_(heads),
      head_size_(width / heads),
      q_(w.linear(prefix + ".q", width, width)),
      k_(w.linear(prefix + ".k", width, width)),
      v_(w.linear(prefix + ".v", width, width)),
      out_(w.linear(prefix + ".out", width, width)),
      relative_(w, prefix + ".relative", blocks::kDistanceFeatures, blocks::kRelativeHidden, heads) {}

void attend_heads(ConstMatrixRef q, ConstMatrixRef k, ConstMatrixRef v, int heads, const MatrixRXf* relative_bias,
                  const RowVectorXf& key_mask, MatrixRXf* o) {
  const Eigen::Index Tq = q.rows(), Tk = k.rows(), dh = q.cols() / heads;
  // Masked keys get no weight (their softmax terms are 0, as libtorch's
  // underflow to 0) unless every key is masked: only the others are attended.
  std::vector<Eigen::Index> keys;
  for (Eigen::Index j = 0; j < Tk; ++j)
    if (key_mask[j] > 0.5f * static_cast<float>(blocks::kMasked)) keys.push_back(j);
  if (keys.empty() || static_cast<Eigen::Index>(keys.size()) == Tk) {
    keys.resize(Tk);
    for (Eigen::Index j = 0; j < Tk; ++j) keys[j] = j;
  }
  const Eigen::Index K = static_cast<Eigen::Index>(keys.size());
  MatrixRXf k_kept(K, k.cols()), v_kept(K, v.cols()), scores(Tq, K);
  for (Eigen::Index n = 0; n < K; ++n) k_kept.row(n) = k.row(keys[n]), v_kept.row(n) = v.row(keys[n]);
  o->resize(Tq, v.cols());
  for (int h = 0; h < heads; ++h) {
    gemm(q.middleCols(h * dh, dh), false, k_kept.middleCols(h * dh, dh), true, scores, 0.0f);
    for (Eigen::Index i = 0; i < Tq; ++i) {
      for (Eigen::Index n = 0; n < K; ++n) {
        const Eigen::Index j = keys[n];
        scores(i, n) += relative_bias ? (*relative_bias)(j - i + Tk - 1, h) + key_mask[j] : key_mask[j];
      }
    }
    softmax_rows(scores);
    gemm(scores, false, v_kept.middleCols(h * dh, dh), false, o->middleCols(h * dh, dh), 0.0f);
  }
}

void RelativeAttention::forward(ConstMatrixRef x, const RowVectorXf& key_mask, ConstMatrixRef offsets,
                                MatrixRXf* y) const {
  MatrixRXf q, k, v, bias, o;
  linear_rows(x, q_, &q);
  q *= static_cast<float>(1.0 / std::sqrt(static_cast<double>(head_size_)));
  linear_rows(x, k_, &k);
  linear_rows(x, v_, &v);
  relative_.forward(offsets, &bias);  // [2T - 1, H]
  attend_heads(q, k, v, heads_, &bias, key_mask, &o);
  linear_rows(o, out_, y);
}

TransformerLayer::TransformerLayer(WeightReader& w, const std::string& prefix, const blocks::TrunkSize& size)
    : norm1_(w, prefix + ".norm1", size.width),
      norm2_(w, prefix + ".norm2", size.width),
      attn_(w, prefix + ".attn", size.width, size.heads),
      ffn_(w, prefix + ".ffn", size.width, size.ffn) {}

void TransformerLayer::forward(MatrixRXf* x, const RowVectorXf& key_mask, ConstMatrixRef offsets) const {
  MatrixRXf n, d;
  norm1_.forward(*x, &n);
  attn_.forward(n, key_mask, offsets, &d);
  *x += d;
  norm2_.forward(*x, &n);
  ffn_.forward(n, &d);
  *x += d;
}

TransformerStage::TransformerStage(WeightReader& w, const std::string& prefix, const blocks::TrunkSize& size,
                                   int inputs, int outputs, bool keyframe_encoding)
    : input_(w, prefix + ".input", inputs, size.width, size.width),
      norm_(w, prefix + ".norm", size.width),
      output_(w, prefix + ".output", size.width, size.width, outputs) {
  if (keyframe_encoding) keyframe_.emplace_back(w, prefix + ".keyframe", blocks::kKeyFeatures, size.width, size.width);
  for (int l = 0; l < size.layers; ++l) layers_.emplace_back(w, prefix + ".layers." + std::to_string(l), size);
}

void TransformerStage::forward(ConstMatrixRef x, ConstMatrixRef key_features, const RowVectorXf& key_mask,
                               ConstMatrixRef offsets, MatrixRXf* y) const {
  MatrixRXf h, e;
  input_.forward(x, &h);
  if (!keyframe_.empty()) {
    keyframe_.front().forward(key_features, &e);
    h += e;
  }
  for (const TransformerLayer& layer : layers_) layer.forward(&h, key_mask, offsets);
  norm_.forward(h, &e);
  output_.forward(e, y);
}

}  // namespace mf::runtime
