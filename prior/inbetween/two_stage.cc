#include "prior/inbetween/two_stage.h"

#include <ATen/ATen.h>
#include <torch/nn/module.h>
#include <torch/nn/modules/activation.h>
#include <torch/nn/modules/container/modulelist.h>
#include <torch/nn/modules/linear.h>
#include <torch/nn/modules/normalization.h>

#include <cmath>
#include <sstream>

#include "prior/motion/errors.h"

namespace mf {

namespace {

// Additive attention mask: large but finite, so a row with every key masked
// gives a uniform softmax instead of NaN.
constexpr double kMasked = -1e9;
// Hidden units of the per-layer relative position MLP.
constexpr int kRelativeHidden = 32;
// Frame distances enter the position MLPs as sinusoids of kFrequencies
// frequencies (periods geometric from 4 frames to twice the window) plus the
// distance divided by the window: plain scalars make positions hard to tell
// apart at initialisation and slow training down.
constexpr int kFrequencies = 8;
constexpr int kDistanceFeatures = 2 * kFrequencies + 1;
// Keyframe encoding inputs: the distance to the previous key, to the next key
// and the fraction of the way between them.
constexpr int kKeyFeatures = 2 * kDistanceFeatures + 1;

struct TwoStageConfig {
  int width = 64;
  int layers = 2;
  int heads = 4;
  int ffn = 128;
  int window = 128;
  double fps = 30.0;

  std::map<std::string, double> to_map() const {
    return {{"width", width}, {"layers", layers}, {"heads", heads}, {"ffn", ffn}, {"window", window}, {"fps", fps}};
  }
};

TwoStageConfig parse_config(const std::map<std::string, double>& values) {
  TwoStageConfig c;
  HyperparameterReader r("twostage", values);
  r.integer("width", 4, 4096, &c.width);
  r.integer("layers", 1, 64, &c.layers);
  r.integer("heads", 1, 64, &c.heads);
  r.integer("ffn", 1, 16384, &c.ffn);
  r.integer("window", 2, 4096, &c.window);
  r.positive("fps", 1000, &c.fps);
  r.check(c.width % c.heads == 0,
          "heads (" + std::to_string(c.heads) + ") must divide width (" + std::to_string(c.width) + ")");
  r.finish();
  return c;
}

// Linear -> PReLU -> Linear.
struct MlpImpl : torch::nn::Module {
  MlpImpl(int in, int hidden, int out) {
    fc1 = register_module("fc1", torch::nn::Linear(in, hidden));
    act = register_module("act", torch::nn::PReLU());
    fc2 = register_module("fc2", torch::nn::Linear(hidden, out));
  }
  at::Tensor forward(const at::Tensor& x) { return fc2->forward(act->forward(fc1->forward(x))); }
  torch::nn::Linear fc1{nullptr}, fc2{nullptr};
  torch::nn::PReLU act{nullptr};
};
TORCH_MODULE(Mlp);

struct FeedForwardImpl : torch::nn::Module {
  FeedForwardImpl(int width, int hidden) {
    fc1 = register_module("fc1", torch::nn::Linear(width, hidden));
    fc2 = register_module("fc2", torch::nn::Linear(hidden, width));
  }
  at::Tensor forward(const at::Tensor& x) { return fc2->forward(at::relu(fc1->forward(x))); }
  torch::nn::Linear fc1{nullptr}, fc2{nullptr};
};
TORCH_MODULE(FeedForward);

// Geometry of one forward pass, shared by every layer of a stage.
struct Positions {
  at::Tensor offsets;         // [2T - 1, kDistanceFeatures] of the key - query offsets -(T-1)..T-1
  at::Tensor relative_index;  // [T, T] long: offset index of (query i, key j)
};

// Frame distances [...] (float, frames) -> [..., kDistanceFeatures].
at::Tensor distance_features(const at::Tensor& frames, int window) {
  at::Tensor i = at::arange(kFrequencies, frames.options());
  const double ratio = std::log(2.0 * window / 4.0) / (kFrequencies - 1);
  at::Tensor omega = (2.0 * M_PI / 4.0) * at::exp(i * -ratio);
  at::Tensor angle = frames.unsqueeze(-1) * omega;
  return at::cat({at::sin(angle), at::cos(angle), frames.unsqueeze(-1) / window}, -1);
}

Positions make_positions(int64_t T, const TwoStageConfig& c, const at::TensorOptions& options) {
  Positions p;
  const double limit = c.window - 1;
  p.offsets = distance_features(at::arange(-(T - 1), T, options).clamp(-limit, limit), c.window);
  at::Tensor t = at::arange(T, at::kLong);
  p.relative_index = t.unsqueeze(0) - t.unsqueeze(1) + (T - 1);
  return p;
}

// Multi-head self-attention with a learned relative position bias per head:
// scores = q . k / sqrt(dh) + b_h(j - i) + mask, b = MLP of the offset features.
struct AttentionImpl : torch::nn::Module {
  AttentionImpl(int width, int heads) : heads_(heads), head_size_(width / heads) {
    q = register_module("q", torch::nn::Linear(width, width));
    k = register_module("k", torch::nn::Linear(width, width));
    v = register_module("v", torch::nn::Linear(width, width));
    out = register_module("out", torch::nn::Linear(width, width));
    relative = register_module("relative", Mlp(kDistanceFeatures, kRelativeHidden, heads));
  }

  // x [B, T, W]; mask [B, 1, 1, T] additive key mask.
  at::Tensor forward(const at::Tensor& x, const at::Tensor& mask, const Positions& pos) {
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

  int64_t heads_, head_size_;
  torch::nn::Linear q{nullptr}, k{nullptr}, v{nullptr}, out{nullptr};
  Mlp relative{nullptr};
};
TORCH_MODULE(Attention);

struct LayerImpl : torch::nn::Module {
  explicit LayerImpl(const TwoStageConfig& c) {
    norm1 = register_module("norm1", torch::nn::LayerNorm(torch::nn::LayerNormOptions({c.width})));
    attn = register_module("attn", Attention(c.width, c.heads));
    norm2 = register_module("norm2", torch::nn::LayerNorm(torch::nn::LayerNormOptions({c.width})));
    ffn = register_module("ffn", FeedForward(c.width, c.ffn));
  }
  at::Tensor forward(at::Tensor x, const at::Tensor& mask, const Positions& pos) {
    x = x + attn->forward(norm1->forward(x), mask, pos);
    return x + ffn->forward(norm2->forward(x));
  }
  torch::nn::LayerNorm norm1{nullptr}, norm2{nullptr};
  Attention attn{nullptr};
  FeedForward ffn{nullptr};
};
TORCH_MODULE(Layer);

// One transformer (context or detail): input MLP, optional keyframe encoding,
// pre-norm layers, final norm, output MLP.
struct StageImpl : torch::nn::Module {
  StageImpl(const TwoStageConfig& c, int inputs, int outputs, bool keyframe_encoding) {
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
  at::Tensor forward(const at::Tensor& x, const at::Tensor& key_features, const at::Tensor& mask,
                     const Positions& pos) {
    at::Tensor h = input->forward(x);
    if (!keyframe.is_empty()) h = h + keyframe->forward(key_features);
    for (auto& layer : layers) h = layer->forward(h, mask, pos);
    return output->forward(norm->forward(h));
  }
  Mlp input{nullptr}, keyframe{nullptr}, output{nullptr};
  torch::nn::ModuleList layer_list{nullptr};
  std::vector<Layer> layers;
  torch::nn::LayerNorm norm{nullptr};
};
TORCH_MODULE(Stage);

// Index of the last frame at or before t where `flag` holds ([B, T] long),
// `none` where there is none. Reversed with `forward` false: first at or after.
at::Tensor nearest_flagged(const at::Tensor& flag, bool forward, int64_t none) {
  const int64_t T = flag.size(1);
  at::Tensor t = at::arange(T, at::kLong).unsqueeze(0).expand_as(flag);
  if (forward) return std::get<0>(at::cummax(at::where(flag, t, at::full_like(t, none)), 1));
  at::Tensor reversed = at::where(flag, t, at::full_like(t, none)).flip(1);
  return std::get<0>(at::cummin(reversed, 1)).flip(1);
}

struct TwoStageNetImpl : torch::nn::Module {
  TwoStageNetImpl(const TwoStageConfig& c, int joints, int feet)
      : config(c), joints(joints), feet(feet), pose_size(joints * 6 + 3) {
    const int inputs = pose_size + joints + 1;
    context = register_module("context", Stage(c, inputs, pose_size, true));
    detail = register_module("detail", Stage(c, inputs, pose_size + feet, false));
    torch::NoGradGuard no_grad;
    detail->output->fc2->weight.mul_(0.1);  // the detail stage starts close to the identity
    detail->output->fc2->bias.zero_();
  }

  // Root positions [B, T, 3] linearly interpolated between the frames where
  // `root_known` [B, T] (bool) holds, held before the first and after the last.
  static at::Tensor interpolate_root(const at::Tensor& root, const at::Tensor& root_known) {
    const int64_t B = root.size(0), T = root.size(1);
    at::Tensor prev = nearest_flagged(root_known, true, -1);
    at::Tensor next = nearest_flagged(root_known, false, T);
    at::Tensor has_prev = (prev >= 0).unsqueeze(-1), has_next = (next < T).unsqueeze(-1);
    at::Tensor known_only = at::where(root_known.unsqueeze(-1), root, at::zeros_like(root));
    at::Tensor pv = known_only.gather(1, prev.clamp(0, T - 1).unsqueeze(-1).expand({B, T, 3}));
    at::Tensor nv = known_only.gather(1, next.clamp(0, T - 1).unsqueeze(-1).expand({B, T, 3}));
    at::Tensor t = at::arange(T, at::kLong).unsqueeze(0);
    at::Tensor w =
        ((t - prev).to(root.scalar_type()) / (next - prev).clamp_min(1).to(root.scalar_type())).unsqueeze(-1);
    at::Tensor both = pv + (nv - pv) * w;
    return at::where(has_prev, at::where(has_next, both, pv), at::where(has_next, nv, at::zeros_like(root)));
  }

  // Keyframe encoding inputs [B, T, kKeyFeatures] from key [B, T] (bool).
  at::Tensor key_features(const at::Tensor& key) const {
    const int64_t T = key.size(1);
    const int64_t far = 2 * static_cast<int64_t>(config.window) + T;
    at::Tensor t = at::arange(T, at::kLong).unsqueeze(0);
    at::Tensor before = (t - nearest_flagged(key, true, -far)).clamp_max(config.window).to(at::kFloat);
    at::Tensor after = (nearest_flagged(key, false, far) - t).clamp_max(config.window).to(at::kFloat);
    at::Tensor span = before + after;
    at::Tensor fraction = at::where(span > 0, before / span.clamp_min(1.0), at::zeros_like(span));
    return at::cat({distance_features(before, config.window), distance_features(after, config.window),
                    fraction.unsqueeze(-1)},
                   -1);
  }

  // pose [B, T, D] raw; known [B, T, J + 1]; valid [B, T]; mean/std [D].
  InbetweenOutput forward(const at::Tensor& pose, const at::Tensor& known_in, const at::Tensor& valid,
                          const at::Tensor& mean, const at::Tensor& scale) {
    const int64_t B = pose.size(0), T = pose.size(1), J = joints, D = pose_size;
    at::Tensor known = known_in * valid.unsqueeze(-1);
    at::Tensor channel_known = known_channel_mask(known, joints) > 0.5;  // [B, T, D]
    at::Tensor normalised = (pose - mean) / scale;
    at::Tensor rotations = at::where(channel_known.narrow(-1, 0, 6 * J), normalised.narrow(-1, 0, 6 * J),
                                     at::zeros({1}, pose.options()));
    at::Tensor root_known = known.select(-1, J) > 0.5;
    at::Tensor root = (interpolate_root(pose.narrow(-1, 6 * J, 3), root_known) - mean.narrow(0, 6 * J, 3)) /
                      scale.narrow(0, 6 * J, 3);
    at::Tensor x = at::cat({rotations, root}, -1);  // normalised input; exact where known

    at::Tensor key = known.amax(-1) > 0.5;
    at::Tensor zero = at::zeros({1}, pose.options());
    at::Tensor masked = at::full({1}, kMasked, pose.options());
    at::Tensor key_mask = at::where(key, zero, masked).view({B, 1, 1, T});
    at::Tensor valid_mask = at::where(valid > 0.5, zero, masked).view({B, 1, 1, T});
    Positions positions = make_positions(T, config, pose.options());

    at::Tensor context_out =
        context->forward(at::cat({x, known}, -1), key_features(key), key_mask, positions);  // normalised
    at::Tensor mixed = at::where(channel_known, x, context_out);
    at::Tensor detail_out = detail->forward(at::cat({mixed, known}, -1), at::Tensor(), valid_mask, positions);

    InbetweenOutput out;
    out.stages.push_back(context_out * scale + mean);
    out.stages.push_back((mixed + detail_out.narrow(-1, 0, D)) * scale + mean);
    out.contact_logits = detail_out.narrow(-1, D, feet);
    return out;
  }

  TwoStageConfig config;
  int joints, feet, pose_size;
  Stage context{nullptr}, detail{nullptr};
};
TORCH_MODULE(TwoStageNet);

class TwoStageModel final : public InbetweenModel {
 public:
  TwoStageModel(const TwoStageConfig& config, const RigInfo& rig)
      : InbetweenModel(rig), config_(config), net_(config, rig.num_joints(), rig.num_feet()) {}

  std::string kind() const override { return kTwoStageKind; }
  std::vector<std::string> stage_names() const override { return {"context", "detail"}; }
  std::map<std::string, double> hyperparameters() const override { return config_.to_map(); }
  std::string describe() const override {
    std::ostringstream s;
    s << "twostage: context " << config_.layers << "x" << config_.width << ", detail " << config_.layers << "x"
      << config_.width << ", " << config_.heads << " heads, ffn " << config_.ffn << ", window " << config_.window
      << " frames at " << config_.fps << " fps";
    return s.str();
  }

  InbetweenOutput forward(const InbetweenBatch& batch) const override {
    const Normalisation n = checked_normalisation(batch, config_.window, "twostage");
    const int64_t D = pose_size();
    return net_->forward(batch.pose.to(at::kFloat), batch.known.to(n.options), batch.valid.to(n.options),
                         n.mean.reshape({D}), n.scale.reshape({D}));
  }

  std::vector<std::pair<std::string, at::Tensor>> named_parameters() const override {
    std::vector<std::pair<std::string, at::Tensor>> out;
    for (const auto& item : net_->named_parameters(true)) out.emplace_back(item.key(), item.value());
    return out;
  }
  void train(bool on) override { net_->train(on); }

 private:
  TwoStageConfig config_;
  mutable TwoStageNet net_;
};

}  // namespace

std::unique_ptr<InbetweenModel> make_two_stage(const std::map<std::string, double>& hyperparameters,
                                               const RigInfo& rig) {
  if (rig.num_joints() < 1) throw InputError("twostage: the rig has no joints");
  return std::make_unique<TwoStageModel>(parse_config(hyperparameters), rig);
}

InbetweenerKind two_stage_kind() {
  return {kTwoStageKind,
          "two-stage transformer",
          "motionfield-twostage.mfm",
          {{"context", "Context Transformer only"}, {"detail", "Context + Detail Transformer"}},
          make_two_stage};
}

}  // namespace mf
