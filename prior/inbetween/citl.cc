#include "prior/inbetween/citl.h"

#include <ATen/ATen.h>
#include <torch/nn/module.h>
#include <torch/nn/modules/conv.h>
#include <torch/nn/modules/linear.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <tuple>

#include "prior/inbetween/network_model.h"
#include "prior/motion/errors.h"
#include "prior/util/module_parameters.h"

namespace mf {

namespace {

// Additive attention mask: large but finite, so a row with every key masked
// gives a uniform softmax instead of NaN.
constexpr double kMasked = -1e9;

struct RmsNormImpl : torch::nn::Module {
  explicit RmsNormImpl(int width) { weight = register_parameter("weight", at::ones({width})); }
  at::Tensor forward(const at::Tensor& x) { return x * at::rsqrt(x.pow(2).mean(-1, true) + 1e-6) * weight; }
  at::Tensor weight;
};
TORCH_MODULE(RmsNorm);

struct FeedForwardImpl : torch::nn::Module {
  FeedForwardImpl(int width, int hidden) {
    up = register_module("up", torch::nn::Linear(width, hidden));
    down = register_module("down", torch::nn::Linear(hidden, width));
  }
  at::Tensor forward(const at::Tensor& x) { return down->forward(at::gelu(up->forward(x))); }
  torch::nn::Linear up{nullptr}, down{nullptr};
};
TORCH_MODULE(FeedForward);

// Multi-head attention. Self-attention when `cross` is false (memory == x).
// bias [B, 1, 1, Tk] is added to the scores (0 or kMasked per key).
struct AttentionImpl : torch::nn::Module {
  AttentionImpl(int width, int heads, bool cross) : heads_(heads), cross_(cross) {
    if (cross) {
      q = register_module("q", torch::nn::Linear(width, width));
      kv = register_module("kv", torch::nn::Linear(width, 2 * width));
    } else {
      qkv = register_module("qkv", torch::nn::Linear(width, 3 * width));
    }
    out = register_module("out", torch::nn::Linear(width, width));
  }
  // x [B or 1, Tq, W], memory [B, Tk, W] -> [B, Tq, W]
  at::Tensor forward(const at::Tensor& x, const at::Tensor& memory, const at::Tensor& bias) {
    const int64_t W = x.size(-1), dh = W / heads_;
    auto split_heads = [&](const at::Tensor& t) {  // [b, n, W] -> [b, H, n, dh]
      return t.unflatten(-1, {heads_, dh}).transpose(1, 2);
    };
    at::Tensor qh, kh, vh;
    if (cross_) {
      qh = split_heads(q->forward(x));
      std::vector<at::Tensor> parts = kv->forward(memory).chunk(2, -1);
      kh = split_heads(parts[0]);
      vh = split_heads(parts[1]);
    } else {
      std::vector<at::Tensor> parts = qkv->forward(x).chunk(3, -1);
      qh = split_heads(parts[0]);
      kh = split_heads(parts[1]);
      vh = split_heads(parts[2]);
    }
    at::Tensor scores = at::matmul(qh * (1.0 / std::sqrt(static_cast<double>(dh))), kh.transpose(-1, -2)) + bias;
    at::Tensor o = at::matmul(at::softmax(scores, -1), vh);  // [B, H, Tq, dh]
    return out->forward(o.transpose(1, 2).flatten(2));
  }
  int64_t heads_;
  bool cross_;
  torch::nn::Linear q{nullptr}, kv{nullptr}, qkv{nullptr}, out{nullptr};
};
TORCH_MODULE(Attention);

// Pre-norm transformer layer (RMSNorm, attention, RMSNorm, GELU feed-forward).
struct LayerImpl : torch::nn::Module {
  LayerImpl(const CitlConfig& c, bool cross) {
    norm1 = register_module("norm1", RmsNorm(c.width));
    attn = register_module("attn", Attention(c.width, c.heads, cross));
    norm2 = register_module("norm2", RmsNorm(c.width));
    ffn = register_module("ffn", FeedForward(c.width, c.ffn));
  }
  // Self-attention: memory undefined. Cross-attention: memory already normalised.
  at::Tensor forward(at::Tensor x, const at::Tensor& memory, const at::Tensor& bias) {
    at::Tensor n = norm1->forward(x);
    x = x + attn->forward(n, memory.defined() ? memory : n, bias);
    return x + ffn->forward(norm2->forward(x));
  }
  RmsNorm norm1{nullptr}, norm2{nullptr};
  Attention attn{nullptr};
  FeedForward ffn{nullptr};
};
TORCH_MODULE(Layer);

struct CitlNetImpl : torch::nn::Module {
  CitlNetImpl(const CitlConfig& c, int joints) : config(c), joints(joints), pose_size(joints * 6 + 3) {
    const int W = c.width;
    input = register_module("input", torch::nn::Linear(pose_size + joints + 1, W - c.time_dim));
    for (int l = 0; l < c.layers; ++l) {
      encoder.push_back(register_module("encoder" + std::to_string(l), Layer(c, false)));
    }
    encoder_norm = register_module("encoder_norm", RmsNorm(W));
    query = register_module("query", torch::nn::Linear(c.time_dim, W));
    for (int l = 0; l < c.layers; ++l) {
      interpolator.push_back(register_module("interpolator" + std::to_string(l), Layer(c, true)));
    }
    interpolator_norm = register_module("interpolator_norm", RmsNorm(W));
    key_ffn = register_module("key_ffn", FeedForward(W, c.ffn));
    conv_in = register_module("conv_in", torch::nn::Conv1d(torch::nn::Conv1dOptions(W, W, 3).padding(1)));
    for (int l = 0; l < c.layers; ++l) {
      synthesis.push_back(register_module("synthesis" + std::to_string(l), Layer(c, false)));
    }
    synthesis_norm = register_module("synthesis_norm", RmsNorm(W));
    conv_out = register_module("conv_out", torch::nn::Conv1d(torch::nn::Conv1dOptions(W, pose_size, 3).padding(1)));
    torch::NoGradGuard no_grad;
    conv_out->weight.mul_(0.1);  // start close to the mean pose
    conv_out->bias.zero_();
  }

  // Sinusoids of the frame index [T, time_dim]; periods geometric from 4 frames
  // to 4 windows so every channel varies over a window.
  at::Tensor time_embedding(int64_t frames) const {
    const int n = config.time_dim / 2;
    at::Tensor i = at::arange(n, at::kFloat);
    double ratio = n > 1 ? std::log(static_cast<double>(config.window)) / (n - 1) : 0.0;
    at::Tensor omega = (2.0 * M_PI / 4.0) * at::exp(i * -ratio);
    at::Tensor angle = at::arange(frames, at::kFloat).unsqueeze(1) * omega;
    return at::cat({at::sin(angle), at::cos(angle)}, -1);
  }

  // x [B, T, C] -> Conv1d over time -> [B, T, C']
  static at::Tensor conv_time(torch::nn::Conv1d& conv, const at::Tensor& x) {
    return conv->forward(x.transpose(1, 2)).transpose(1, 2);
  }

  // pose [B, T, D] raw; known [B, T, J + 1]; valid [B, T]; mean/std [D].
  at::Tensor forward(const at::Tensor& pose_in, const at::Tensor& known_in, const at::Tensor& valid,
                     const at::Tensor& mean, const at::Tensor& scale) {
    const int64_t B = pose_in.size(0), T = pose_in.size(1), J = joints;
    at::Tensor valid3 = valid.unsqueeze(-1);
    at::Tensor known = known_in * valid3;
    at::Tensor channel_known = known_channel_mask(known, joints) > 0.5;  // [B, T, D]
    at::Tensor pose = at::where(channel_known, pose_in, at::zeros_like(pose_in));

    // Seq-RC: mean known root position over the window.
    at::Tensor root_known = known.narrow(-1, J, 1);
    at::Tensor center = (pose.narrow(-1, 6 * J, 3) * root_known).sum(1) / root_known.sum(1).clamp_min(1.0);
    at::Tensor shift = at::constant_pad_nd(center, {6 * J, 0}).unsqueeze(1);  // [B, 1, D]
    at::Tensor rotation_channels = (at::arange(pose_size, at::kLong) < 6 * J).to(at::kFloat);
    at::Tensor offset = mean * rotation_channels + shift;

    at::Tensor x = at::where(channel_known, (pose - offset) / scale, at::zeros_like(pose));
    at::Tensor is_key = known.amax(-1);  // [B, T] in {0, 1}
    at::Tensor valid_bias = ((1.0 - valid) * kMasked).view({B, 1, 1, T});
    at::Tensor pe = time_embedding(T);

    // The keyframes of each window first, in time order: index [B, K] with
    // K = the largest key count in the batch; slots past a window's own count
    // hold non-key frames and are masked out of every attention.
    const int64_t K = std::max<int64_t>(1, is_key.sum(1).max().item<int64_t>());
    at::Tensor rank = is_key * (2.0 * T) - at::arange(T, is_key.options());
    at::Tensor index = std::get<1>(rank.sort(-1, /*descending=*/true)).narrow(1, 0, K);  // [B, K]
    at::Tensor key_valid = is_key.gather(1, index);
    at::Tensor key_bias = ((1.0 - key_valid) * kMasked).view({B, 1, 1, K});
    auto take_keys = [&](const at::Tensor& t) {  // [B, T, C] -> [B, K, C]
      return t.gather(1, index.unsqueeze(-1).expand({B, K, t.size(-1)}));
    };

    // Stage I: keyframe encoder over the keyframe tokens only.
    at::Tensor h = at::cat({input->forward(take_keys(at::cat({x, known}, -1))),
                            pe.index_select(0, index.flatten()).view({B, K, config.time_dim})},
                           -1);
    for (auto& layer : encoder) h = layer->forward(h, at::Tensor(), key_bias);
    h = encoder_norm->forward(h);

    // Stage II: time queries cross-attend to the keyframe tokens.
    at::Tensor q = query->forward(pe).unsqueeze(0);
    for (auto& layer : interpolator) q = layer->forward(q, h, key_bias);
    q = interpolator_norm->forward(q).expand({B, T, config.width});

    // Stage III: synthesis over all frames in time order. Padding tokens are
    // zeroed before each convolution so they act like the convolution's own
    // zero padding.
    at::Tensor keys = at::zeros({B, T, config.width}, h.options())
                          .scatter(1, index.unsqueeze(-1).expand({B, K, config.width}), h + key_ffn->forward(h));
    at::Tensor s = at::where(is_key.unsqueeze(-1) > 0.5, keys, q) * valid3;
    s = conv_time(conv_in, s);
    for (auto& layer : synthesis) s = layer->forward(s, at::Tensor(), valid_bias);
    s = synthesis_norm->forward(s) * valid3;
    at::Tensor y = conv_time(conv_out, s) * scale + offset;
    return at::where(channel_known, pose, y);
  }

  CitlConfig config;
  int joints, pose_size;
  torch::nn::Linear input{nullptr}, query{nullptr};
  std::vector<Layer> encoder, interpolator, synthesis;
  RmsNorm encoder_norm{nullptr}, interpolator_norm{nullptr}, synthesis_norm{nullptr};
  FeedForward key_ffn{nullptr};
  torch::nn::Conv1d conv_in{nullptr}, conv_out{nullptr};
};
TORCH_MODULE(CitlNet);

class CitlModel final : public NetworkModel<CitlConfig, CitlNet> {
 public:
  CitlModel(const CitlConfig& config, const RigInfo& rig)
      : NetworkModel(config, rig, CitlNet(config, rig.num_joints())) {}

  std::string kind() const override { return kCitlKind; }
  std::vector<std::string> stage_names() const override { return {"citl"}; }
  std::string describe() const override {
    std::ostringstream s;
    s << "citl: keyframe encoder " << config_.layers << "x" << config_.width << ", interpolator "
      << config_.layers << "x" << config_.width << ", synthesis " << config_.layers << "x" << config_.width
      << ", " << config_.heads << " heads, ffn " << config_.ffn << ", time embedding " << config_.time_dim
      << ", window " << config_.window << " frames at " << config_.fps << " fps";
    return s.str();
  }

  InbetweenOutput forward(const InbetweenBatch& batch) const override {
    const Normalisation n = checked_normalisation(batch, config_.window, "CITL");
    const int64_t D = pose_size();
    InbetweenOutput out;
    out.stages.push_back(net_->forward(batch.pose.to(at::kFloat), batch.known.to(n.options), batch.valid.to(n.options),
                                       n.mean.reshape({D}), n.scale.reshape({D})));
    return out;
  }
};

}  // namespace

std::unique_ptr<InbetweenModel> make_citl(const std::map<std::string, double>& hyperparameters, const RigInfo& rig) {
  return make_network_model<CitlModel>("CITL", parse_citl_config(hyperparameters), rig);
}

int64_t citl_parameter_count(const std::map<std::string, double>& hyperparameters, const RigInfo& rig) {
  const CitlConfig c = parse_citl_config(hyperparameters);
  const int64_t W = c.width, pose_size = rig.num_joints() * 6 + 3;
  auto linear = [](int64_t in, int64_t out) { return in * out + out; };
  const int64_t feed_forward = linear(W, c.ffn) + linear(c.ffn, W);
  // Self- and cross-attention layers hold the same count: qkv (W -> 3W) or q + kv.
  const int64_t layer = 2 * W + linear(W, 3 * W) + linear(W, W) + feed_forward;
  return linear(pose_size + rig.num_joints() + 1, W - c.time_dim) + 3 * c.layers * layer + 3 * W +
         linear(c.time_dim, W) + feed_forward + (3 * W * W + W) + (3 * W * pose_size + pose_size);
}

InbetweenNetwork citl_network() { return {make_citl, citl_parameter_count}; }

}  // namespace mf
