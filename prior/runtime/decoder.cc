#include "prior/runtime/decoder.h"

#include <atomic>
#include <cmath>
#include <string>

#include "prior/motion/errors.h"

namespace mf::runtime {

namespace {

constexpr float kLayerNormEps = 1e-5f;  // torch::nn::LayerNorm's default

uint64_t next_decoder_id() {
  static std::atomic<uint64_t> id{0};
  return ++id;
}

}  // namespace

void decoder_time_features(const Eigen::Ref<const Eigen::VectorXd>& frames, int window, int frequencies,
                           MatrixRXf* pe) {
  pe->resize(frames.size(), 2 * frequencies);
  for (Eigen::Index s = 0; s < frames.size(); ++s) {
    const float t = static_cast<float>(frames[s]) / static_cast<float>(window) * 2.0f - 1.0f;
    for (int i = 0; i < frequencies; ++i) {
      const float a = t * std::ldexp(1.0f, i);
      (*pe)(s, i) = std::sin(a);
      (*pe)(s, frequencies + i) = std::cos(a);
    }
  }
}

NemfDecoder::NemfDecoder(const NemfConfig& config, int joints, WeightReader& weights)
    : config_(config), joints_(joints) {
  const int W = config.decoder_width, L = config.decoder_layers;
  for (int l = 0; l < L; ++l) {
    const std::string p = "decoder.", s = std::to_string(l);
    Layer layer;
    layer.pe = WeightMatrix(weights.matrix(p + "pe" + s + ".weight", W, 2 * config.pe_frequencies));
    layer.pe_bias = weights.vector(p + "pe" + s + ".bias", W);
    layer.zl = weights.matrix(p + "zl" + s + ".weight", W, config.zl);
    if (l > 0) layer.hidden = WeightMatrix(weights.matrix(p + "h" + s + ".weight", W, W));
    if (l >= L - config.zg_layers) layer.zg = weights.matrix(p + "zg" + s + ".weight", W, config.zg);
    layer.norm_weight = weights.vector(p + "norm" + s + ".weight", W);
    layer.norm_bias = weights.vector(p + "norm" + s + ".bias", W);
    layers_.push_back(std::move(layer));
  }
  head_ = WeightMatrix(weights.matrix("decoder.head.weight", joints * 6, W));
  head_bias_ = weights.vector("decoder.head.bias", joints * 6);
  // The head's output is centred on the identity rotation's 6D (1, 0, 0, 0, 1, 0).
  RowVectorXf identity = RowVectorXf::Zero(joints * 6);
  for (int j = 0; j < joints; ++j) identity[6 * j] = identity[6 * j + 4] = 1.0f;
  head_bias_ += identity;
  id_ = next_decoder_id();
}

void NemfDecoder::add_latent_parts(const Eigen::Ref<const Eigen::VectorXf>& z_l,
                                   const Eigen::Ref<const Eigen::VectorXf>& z_g, DecoderWorkspace* ws) const {
  if (z_l.size() != config_.zl || z_g.size() != config_.zg) {
    throw InputError("decode: expected z_l of " + std::to_string(config_.zl) + " and z_g of " +
                     std::to_string(config_.zg) + " values, got " + std::to_string(z_l.size()) + " and " +
                     std::to_string(z_g.size()));
  }
  ws->latent_part.resize(layers_.size());
  for (size_t l = 0; l < layers_.size(); ++l) {
    Eigen::VectorXf& part = ws->latent_part[l];
    part = layers_[l].pe_bias.transpose();
    gemv(layers_[l].zl, false, z_l, part, 1.0f);
    if (layers_[l].zg.size()) gemv(layers_[l].zg, false, z_g, part, 1.0f);
  }
}

void NemfDecoder::time_parts(const Eigen::Ref<const Eigen::VectorXd>& frames, DecoderWorkspace* ws) const {
  if (ws->time_decoder == id_ && ws->time_frames.size() == frames.size() && ws->time_frames == frames) return;
  ws->time_decoder = 0;  // until complete
  decoder_time_features(frames, config_.window, config_.pe_frequencies, &ws->pe);
  ws->time_part.resize(layers_.size());
  for (size_t l = 0; l < layers_.size(); ++l) {
    ws->time_part[l].resize(frames.size(), config_.decoder_width);
    gemm(ws->pe, false, layers_[l].pe, true, ws->time_part[l], 0.0f);
  }
  ws->time_frames = frames;
  ws->time_decoder = id_;
}

void NemfDecoder::decode(const Eigen::Ref<const Eigen::VectorXd>& frames, const Eigen::Ref<const Eigen::VectorXf>& z_l,
                         const Eigen::Ref<const Eigen::VectorXf>& z_g, DecoderWorkspace* ws, MatrixRXf* out) const {
  const size_t L = layers_.size();
  const Eigen::Index S = frames.size();
  time_parts(frames, ws);
  add_latent_parts(z_l, z_g, ws);
  ws->pre.resize(L);
  ws->hidden.resize(L);
  ws->mean.resize(L);
  ws->rstd.resize(L);
  for (size_t l = 0; l < L; ++l) {
    const Layer& layer = layers_[l];
    MatrixRXf& a = ws->pre[l];
    a = ws->time_part[l];
    a.rowwise() += ws->latent_part[l].transpose();
    if (l > 0) gemm(ws->hidden[l - 1], false, layer.hidden, true, a, 1.0f);
    layer_norm_rows(a, layer.norm_weight, layer.norm_bias, kLayerNormEps, &ws->hidden[l], &ws->mean[l],
                    &ws->rstd[l]);
    ws->hidden[l] = ws->hidden[l].cwiseMax(0.0f);
  }
  out->resize(S, head_.rows());
  out->rowwise() = head_bias_;
  gemm(ws->hidden[L - 1], false, head_, true, *out, 1.0f);
}

void NemfDecoder::decode_vjp(DecoderWorkspace* ws, ConstMatrixRef g_out, Eigen::VectorXf* g_zl,
                             Eigen::VectorXf* g_zg) const {
  const Eigen::Index S = ws->pe.rows(), W = config_.decoder_width;
  if (ws->pre.size() != layers_.size() || g_out.rows() != S || g_out.cols() != head_.rows()) {
    throw InputError("decode_vjp: expected the gradient [" + std::to_string(S) + ", " +
                     std::to_string(head_.rows()) + "] of the workspace's last decode");
  }
  g_zl->setZero(config_.zl);
  g_zg->setZero(config_.zg);
  ws->g.resize(S, W);
  gemm(g_out, false, head_, false, ws->g, 0.0f);
  for (size_t l = layers_.size(); l-- > 0;) {
    const Layer& layer = layers_[l];
    leaky_relu_gradient(ws->hidden[l], 0.0f, ws->g);  // through the ReLU
    layer_norm_rows_gradient(ws->g, ws->pre[l], ws->mean[l], ws->rstd[l], layer.norm_weight, &ws->g_pre);
    ws->columns = ws->g_pre.colwise().sum().transpose();
    gemv(layer.zl, true, ws->columns, *g_zl, 1.0f);
    if (layer.zg.size()) gemv(layer.zg, true, ws->columns, *g_zg, 1.0f);
    if (l > 0) gemm(ws->g_pre, false, layer.hidden, false, ws->g, 0.0f);
  }
}

int64_t NemfDecoder::forward_flops(int64_t S) const {
  const int64_t W = config_.decoder_width, L = config_.decoder_layers;
  const int64_t latent = 2 * W * (config_.zl * L + config_.zg * config_.zg_layers);
  return latent + S * (2 * W * W * (L - 1) + 2 * W * head_.rows());
}

int64_t NemfDecoder::vjp_flops(int64_t S) const {
  const int64_t W = config_.decoder_width, L = config_.decoder_layers;
  const int64_t latent = 2 * W * (config_.zl * L + config_.zg * config_.zg_layers);
  return latent + S * (2 * W * head_.rows() + 2 * W * W * (L - 1));
}

}  // namespace mf::runtime
