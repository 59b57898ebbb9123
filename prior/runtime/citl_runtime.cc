#include "prior/runtime/citl_runtime.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "prior/inbetween/transformer_sizes.h"
#include "prior/runtime/inbetween_inputs.h"
#include "prior/runtime/transformer_blocks.h"

namespace mf::runtime {

namespace {

constexpr float kRmsEps = 1e-6f;

// x * rsqrt(mean(x^2) + 1e-6) * weight per row.
class RmsNorm {
 public:
  RmsNorm(WeightReader& w, const std::string& prefix, int width) : weight_(w.vector(prefix + ".weight", width)) {}
  void forward(ConstMatrixRef x, MatrixRXf* y) const {
    y->resize(x.rows(), x.cols());
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      const float r = 1.0f / std::sqrt(x.row(i).squaredNorm() / static_cast<float>(x.cols()) + kRmsEps);
      y->row(i) = ((x.row(i).array() * r) * weight_.array()).matrix();
    }
  }

 private:
  RowVectorXf weight_;
};

// up -> GELU (erf) -> down.
class GeluFeedForward {
 public:
  GeluFeedForward(WeightReader& w, const std::string& prefix, int width, int hidden)
      : up_(w.linear(prefix + ".up", hidden, width)), down_(w.linear(prefix + ".down", width, hidden)) {}
  void forward(ConstMatrixRef x, MatrixRXf* y) const {
    MatrixRXf h;
    linear_rows(x, up_, &h);
    const float r = static_cast<float>(M_SQRT1_2);
    for (Eigen::Index i = 0; i < h.size(); ++i) h.data()[i] = h.data()[i] * 0.5f * (1.0f + std::erf(h.data()[i] * r));
    linear_rows(h, down_, y);
  }

 private:
  Conv1dWeights up_, down_;
};

// Multi-head attention without position terms: self (qkv) or cross (q, kv).
class PlainAttention {
 public:
  PlainAttention(WeightReader& w, const std::string& prefix, int width, int heads, bool cross)
      : heads_(heads), cross_(cross), out_(w.linear(prefix + ".out", width, width)) {
    if (cross) {
      q_ = w.linear(prefix + ".q", width, width);
      kv_ = w.linear(prefix + ".kv", 2 * width, width);
    } else {
      qkv_ = w.linear(prefix + ".qkv", 3 * width, width);
    }
  }
  // x [Tq, W], memory [Tk, W] (x itself for self-attention), key_bias [Tk].
  void forward(ConstMatrixRef x, ConstMatrixRef memory, const RowVectorXf& key_bias, MatrixRXf* y) const {
    const Eigen::Index W = x.cols();
    MatrixRXf q, kv, o;
    if (cross_) {
      linear_rows(x, q_, &q);
      linear_rows(memory, kv_, &kv);
    } else {
      linear_rows(x, qkv_, &kv);
      q = kv.leftCols(W);
      kv = kv.rightCols(2 * W).eval();
    }
    q *= static_cast<float>(1.0 / std::sqrt(static_cast<double>(W / heads_)));
    attend_heads(q, kv.leftCols(W), kv.rightCols(W), heads_, nullptr, key_bias, &o);
    linear_rows(o, out_, y);
  }

 private:
  int heads_;
  bool cross_;
  Conv1dWeights q_, kv_, qkv_, out_;
};

// Pre-norm layer: RMSNorm, attention, RMSNorm, GELU feed-forward.
class CitlLayer {
 public:
  CitlLayer(WeightReader& w, const std::string& prefix, const CitlConfig& c, bool cross)
      : norm1_(w, prefix + ".norm1", c.width),
        norm2_(w, prefix + ".norm2", c.width),
        attn_(w, prefix + ".attn", c.width, c.heads, cross),
        ffn_(w, prefix + ".ffn", c.width, c.ffn) {}
  // In place on x; memory null for self-attention (else already normalised).
  void forward(MatrixRXf* x, const MatrixRXf* memory, const RowVectorXf& key_bias) const {
    MatrixRXf n, d;
    norm1_.forward(*x, &n);
    attn_.forward(n, memory ? *memory : n, key_bias, &d);
    *x += d;
    norm2_.forward(*x, &n);
    ffn_.forward(n, &d);
    *x += d;
  }

 private:
  RmsNorm norm1_, norm2_;
  PlainAttention attn_;
  GeluFeedForward ffn_;
};

std::vector<CitlLayer> citl_layers(WeightReader& w, const std::string& name, const CitlConfig& c, bool cross) {
  std::vector<CitlLayer> layers;
  for (int l = 0; l < c.layers; ++l) layers.emplace_back(w, name + std::to_string(l), c, cross);
  return layers;
}

// y [T, out] of x [T, in] through a kernel-3 convolution with zero padding 1.
void conv_time(ConstMatrixRef x, const Conv1dWeights& conv, MatrixRXf* y) {
  MatrixRXf padded = MatrixRXf::Zero(x.rows() + 2, x.cols());
  padded.middleRows(1, x.rows()) = x;
  conv1d(padded, conv, 1, y);
}

// Sinusoids of the frame index [T, time_dim] (CitlNetImpl::time_embedding).
MatrixRXf time_embedding(int T, const CitlConfig& c) {
  const int n = c.time_dim / 2;
  const float ratio = n > 1 ? static_cast<float>(std::log(static_cast<double>(c.window)) / (n - 1)) : 0.0f;
  const float base = static_cast<float>(2.0 * M_PI / 4.0);
  MatrixRXf pe(T, c.time_dim);
  for (int i = 0; i < n; ++i) {
    const float omega = base * std::exp(static_cast<float>(i) * -ratio);
    for (int t = 0; t < T; ++t) {
      const float angle = static_cast<float>(t) * omega;
      pe(t, i) = std::sin(angle);
      pe(t, n + i) = std::cos(angle);
    }
  }
  return pe;
}

}  // namespace

struct CitlRuntime::Network {
  Network(const CitlConfig& c, int joints, WeightReader& w)
      : input(w.linear("input", c.width - c.time_dim, joints * 7 + 4)),
        encoder(citl_layers(w, "encoder", c, false)),
        encoder_norm(w, "encoder_norm", c.width),
        query(w.linear("query", c.width, c.time_dim)),
        interpolator(citl_layers(w, "interpolator", c, true)),
        interpolator_norm(w, "interpolator_norm", c.width),
        key_ffn(w, "key_ffn", c.width, c.ffn),
        conv_in(w.conv("conv_in", c.width, c.width, 3)),
        synthesis(citl_layers(w, "synthesis", c, false)),
        synthesis_norm(w, "synthesis_norm", c.width),
        conv_out(w.conv("conv_out", joints * 6 + 3, c.width, 3)) {}

  Conv1dWeights input;
  std::vector<CitlLayer> encoder;
  RmsNorm encoder_norm;
  Conv1dWeights query;
  std::vector<CitlLayer> interpolator;
  RmsNorm interpolator_norm;
  GeluFeedForward key_ffn;
  Conv1dWeights conv_in;
  std::vector<CitlLayer> synthesis;
  RmsNorm synthesis_norm;
  Conv1dWeights conv_out;
};

CitlRuntime::CitlRuntime(const CitlConfig& config, const RigInfo& rig, InbetweenNormalisation normalisation,
                         WeightReader& w)
    : InbetweenerRuntime(rig, std::move(normalisation)),
      config_(config),
      net_(std::make_unique<const Network>(config, rig.num_joints(), w)) {}

CitlRuntime::~CitlRuntime() = default;

namespace {

// Sequence-level re-centring: the mean known root position over the window
// replaces the root channels' mean; rotation channels keep theirs.
RowVectorXf recentred_offset(const MatrixRXf& pose, const MatrixRXf& known, const RowVectorXf& mean, int joints) {
  const Eigen::VectorXf root_known = known.col(joints);
  RowVectorXf offset = mean;
  offset.tail(3) = (pose.rightCols(3).array().colwise() * root_known.array()).colwise().sum() /
                   std::max(root_known.sum(), 1.0f);
  return offset;
}

// The keyframes first, in time order, then the other frames: the first K
// (the key count, at least 1) and the additive mask of those that are not keys.
std::vector<int> key_order(const std::vector<bool>& key, RowVectorXf* key_bias) {
  std::vector<int> index;
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t t = 0; t < key.size(); ++t)
      if (key[t] == (pass == 0)) index.push_back(static_cast<int>(t));
  }
  const size_t K = std::max<size_t>(1, std::count(key.begin(), key.end(), true));
  index.resize(K);
  key_bias->resize(static_cast<Eigen::Index>(K));
  for (size_t k = 0; k < K; ++k) (*key_bias)[k] = key[index[k]] ? 0.0f : static_cast<float>(blocks::kMasked);
  return index;
}

MatrixRXf rows_at(const MatrixRXf& x, const std::vector<int>& index) {
  MatrixRXf out(static_cast<Eigen::Index>(index.size()), x.cols());
  for (size_t k = 0; k < index.size(); ++k) out.row(k) = x.row(index[k]);
  return out;
}

}  // namespace

void CitlRuntime::forward(const InbetweenWindow& in, InbetweenResult* out) const {
  const int T = checked_frames(in, config_.window, "CITL");
  const int J = rig().num_joints(), D = pose_size(), W = config_.width;
  const InbetweenNormalisation& n = normalisation();
  const Network& net = *net_;
  const MaskedWindow m = masked_window(in, n, J);
  const MatrixRXf pose = where_known(m.channel_known, in.pose, MatrixRXf::Zero(T, D));
  const RowVectorXf offset = recentred_offset(pose, m.known, n.mean, J);
  const MatrixRXf x = where_known(
      m.channel_known, ((pose.array().rowwise() - offset.array()).rowwise() / n.scale.array()).matrix(),
      MatrixRXf::Zero(T, D));
  RowVectorXf key_bias;
  const std::vector<int> index = key_order(m.key, &key_bias);
  const MatrixRXf pe = time_embedding(T, config_);

  // Stage I: the keyframe encoder over the keyframe tokens.
  MatrixRXf projected, h(index.size(), W), keys, ffn;
  linear_rows(rows_at(concat_columns(x, m.known), index), net.input, &projected);
  h << projected, rows_at(pe, index);
  for (const CitlLayer& layer : net.encoder) layer.forward(&h, nullptr, key_bias);
  net.encoder_norm.forward(h, &keys);
  // Stage II: time queries cross-attend to the keyframe tokens.
  MatrixRXf q, queries;
  linear_rows(pe, net.query, &q);
  for (const CitlLayer& layer : net.interpolator) layer.forward(&q, &keys, key_bias);
  net.interpolator_norm.forward(q, &queries);
  // Stage III: synthesis over every frame in time order.
  net.key_ffn.forward(keys, &ffn);
  for (size_t k = 0; k < index.size(); ++k) {
    if (m.key[index[k]]) queries.row(index[k]) = keys.row(k) + ffn.row(k);
  }
  queries = (queries.array().colwise() * in.valid.array()).matrix();
  MatrixRXf s, y;
  conv_time(queries, net.conv_in, &s);
  const RowVectorXf valid_bias = ((1.0f - in.valid.array()) * static_cast<float>(blocks::kMasked)).matrix().transpose();
  for (const CitlLayer& layer : net.synthesis) layer.forward(&s, nullptr, valid_bias);
  net.synthesis_norm.forward(s, &h);
  conv_time((h.array().colwise() * in.valid.array()).matrix(), net.conv_out, &y);
  y = ((y.array().rowwise() * n.scale.array()).rowwise() + offset.array()).matrix();
  *out = InbetweenResult();
  out->stages.push_back(where_known(m.channel_known, pose, y));
}

}  // namespace mf::runtime
