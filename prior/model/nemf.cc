#include "prior/model/nemf.h"

#include <torch/nn/module.h>
#include <torch/nn/modules/conv.h>
#include <torch/nn/modules/linear.h>
#include <torch/nn/modules/normalization.h>
#include <torch/nn/init.h>
#include <torch/csrc/autograd/custom_function.h>
#include <ATen/ATen.h>
#include <ATen/Parallel.h>

#include <cmath>
#include <utility>

#include "prior/motion/errors.h"
#include "prior/motion/rotations_torch.h"
#include "prior/util/module_parameters.h"

namespace mf {

namespace {

constexpr int kFeaturesPerJoint = 15;

at::Tensor lrelu(const at::Tensor& x) { return at::leaky_relu(x, 0.2); }

// The frozen networks' single-window nodes below split a dense window's frames
// into two halves when there are threads to run them, from 64 frames up
// (kNemfParallelFrames):
// smaller matrix products lose more to BLAS's packing than a second core
// gains, and on one thread the halves only cost (the GMP's halos). Results
// therefore depend on the thread count, by rounding.
int64_t num_chunks(int64_t frames) { return frames >= kNemfParallelFrames && at::get_num_threads() > 1 ? 2 : 1; }

// Chunk k of `chunks` over `frames` frames: its first frame and frame count.
std::pair<int64_t, int64_t> chunk_rows(int64_t frames, int64_t chunks, int64_t k) {
  const int64_t begin = frames * k / chunks, end = frames * (k + 1) / chunks;
  return {begin, end - begin};
}

// Runs body(k, first frame, frame count) for each chunk of `frames` frames
// (chunk_rows), on as many threads as there are chunks and threads, with grad
// mode off (worker threads do not inherit the caller's).
template <class Body>
void for_each_chunk(int64_t frames, int64_t chunks, const Body& body) {
  at::parallel_for(0, chunks, 1, [&](int64_t c0, int64_t c1) {
    at::NoGradGuard no_grad;
    for (int64_t k = c0; k < c1; ++k) {
      const auto [r0, rows] = chunk_rows(frames, chunks, k);
      body(k, r0, rows);
    }
  });
}

// Whether every parameter of `m` is frozen.
bool all_frozen(const torch::nn::Module& m) {
  for (const auto& p : m.parameters()) {
    if (p.requires_grad()) return false;
  }
  return true;
}

// Temporal convolution whose weights connect each joint only to itself, its
// parent and its children (a skeleton-aware convolution with distance 1).
struct SkeletonConvImpl : torch::nn::Module {
  SkeletonConvImpl(const std::vector<int>& parents, int cin, int cout, int kernel, int stride, int padding)
      : stride_(stride), padding_(padding) {
    const int J = static_cast<int>(parents.size());
    at::Tensor adjacency = at::eye(J, at::kFloat);
    for (int j = 1; j < J; ++j) {
      adjacency[j][parents[j]] = 1.0f;
      adjacency[parents[j]][j] = 1.0f;
    }
    // [J * cout, J * cin, 1]: joint blocks of the adjacency.
    at::Tensor mask = adjacency.repeat_interleave(cout, 0).repeat_interleave(cin, 1).unsqueeze(-1);
    mask_ = register_buffer("mask", mask);
    at::Tensor degree = adjacency.sum(1).repeat_interleave(cout, 0).view({-1, 1, 1});
    at::Tensor bound = at::rsqrt(degree * (cin * kernel));
    // In place: the same values as (rand * 2 - 1) * bound * mask without four
    // weight-sized temporaries (fresh memory is slow to touch; see FileBytes).
    weight_ = register_parameter("weight", at::rand({J * cout, J * cin, kernel}).mul_(2).sub_(1).mul_(bound).mul_(mask));
    bias_ = register_parameter("bias", at::zeros({J * cout}));
  }
  // Frozen, the weights are masked once, in place (a no-op on trained weights,
  // whose masked entries never leave zero; it adds no memory), and forward skips
  // the weight-sized product that was most of an encode. Forward skips it only
  // while the weights are unchanged since (their version counter), so a later
  // in-place edit is still masked, and it never writes: frozen models are shared
  // between threads.
  void set_frozen(bool frozen) {
    at::NoGradGuard no_grad;
    frozen_ = frozen;
    if (frozen) weight_.mul_(mask_);
    masked_version_ = weight_._version();
  }
  at::Tensor forward(const at::Tensor& x) {
    const bool masked = frozen_ && !weight_.requires_grad() && weight_._version() == masked_version_;
    return at::conv1d(x, masked ? weight_ : weight_ * mask_, bias_, {stride_}, {padding_});
  }
  int stride_, padding_;
  at::Tensor weight_, bias_, mask_;
  bool frozen_ = false;
  int64_t masked_version_ = 0;
};
TORCH_MODULE(SkeletonConv);

struct LocalEncoderImpl : torch::nn::Module {
  LocalEncoderImpl(const NemfConfig& c, const std::vector<int>& parents) : joints_(static_cast<int>(parents.size())) {
    int cin = kFeaturesPerJoint + 1;  // + mask channel
    int ch = c.encoder_channels;
    for (int i = 0; i < 4; ++i) {
      int cout = ch * std::min(1 << i, 2);
      convs_.push_back(register_module("conv" + std::to_string(i), SkeletonConv(parents, cin, cout, 4, 2, 1)));
      norms_.push_back(register_module("norm" + std::to_string(i),
                                       torch::nn::GroupNorm(torch::nn::GroupNormOptions(joints_, joints_ * cout))));
      cin = cout;
    }
    mix_ = register_module("mix", torch::nn::Conv1d(torch::nn::Conv1dOptions(joints_ * cin, 256, 1)));
    head_ = register_module("head", torch::nn::Linear(256 * (c.window / 16), 2 * c.zl));
  }
  void set_frozen(bool frozen) {
    for (auto& conv : convs_) conv->set_frozen(frozen);
  }
  at::Tensor forward(at::Tensor x) {  // [B, J * 16, window] -> [B, 2 * zl]
    for (size_t i = 0; i < convs_.size(); ++i) x = lrelu(norms_[i]->forward(convs_[i]->forward(x)));
    x = lrelu(mix_->forward(x));
    return head_->forward(x.flatten(1));
  }
  int joints_;
  std::vector<SkeletonConv> convs_;
  std::vector<torch::nn::GroupNorm> norms_;
  torch::nn::Conv1d mix_{nullptr};
  torch::nn::Linear head_{nullptr};
};
TORCH_MODULE(LocalEncoder);

struct GlobalEncoderImpl : torch::nn::Module {
  explicit GlobalEncoderImpl(const NemfConfig& c) {
    const int channels[5] = {7, 64, 128, 128, 128};
    for (int i = 0; i < 4; ++i) {
      convs_.push_back(register_module(
          "conv" + std::to_string(i),
          torch::nn::Conv1d(torch::nn::Conv1dOptions(channels[i], channels[i + 1], 4).stride(2).padding(1))));
    }
    head_ = register_module("head", torch::nn::Linear(128 * (c.window / 16), 2 * c.zg));
  }
  at::Tensor forward(at::Tensor x) {  // [B, 7, window] -> [B, 2 * zg]
    for (auto& conv : convs_) x = lrelu(conv->forward(x));
    return head_->forward(x.flatten(1));
  }
  std::vector<torch::nn::Conv1d> convs_;
  torch::nn::Linear head_{nullptr};
};
TORCH_MODULE(GlobalEncoder);

// The MLP f(t; z_l, z_g). Each layer's Linear over [h, PE(t), z_l, (z_g)] is
// split by input so the latent parts are computed once per window, not per frame.
struct DecoderImpl : torch::nn::Module {
  DecoderImpl(const NemfConfig& c, int joints) : config_(c), joints_(joints) {
    const int W = c.decoder_width;
    for (int l = 0; l < c.decoder_layers; ++l) {
      std::string s = std::to_string(l);
      pe_.push_back(register_module("pe" + s, torch::nn::Linear(2 * c.pe_frequencies, W)));
      zl_.push_back(register_module("zl" + s, torch::nn::Linear(torch::nn::LinearOptions(c.zl, W).bias(false))));
      hidden_.push_back(l == 0 ? nullptr
                               : register_module("h" + s, torch::nn::Linear(torch::nn::LinearOptions(W, W).bias(false))));
      zg_.push_back(l < c.decoder_layers - c.zg_layers
                        ? nullptr
                        : register_module("zg" + s, torch::nn::Linear(torch::nn::LinearOptions(c.zg, W).bias(false))));
      norms_.push_back(register_module("norm" + s, torch::nn::LayerNorm(torch::nn::LayerNormOptions({W}))));
    }
    head_ = register_module("head", torch::nn::Linear(W, joints * 6));
    torch::NoGradGuard no_grad;
    head_->weight.mul_(0.1);
    head_->bias.zero_();
  }
  // pe [B or 1, S, 2F], z_l [B, zl], z_g [B, zg] -> 6D [B, S, J, 6]
  at::Tensor forward(const at::Tensor& pe, const at::Tensor& z_l, const at::Tensor& z_g) {
    if (frozen_path_applies(pe, z_l, z_g)) return frozen_forward(pe, z_l, z_g);
    at::Tensor h;
    for (int l = 0; l < config_.decoder_layers; ++l) {
      at::Tensor a = pe_[l]->forward(pe) + latent_part(zl_[l], z_l);
      if (hidden_[l]) a = a + hidden_[l]->forward(h);
      if (zg_[l]) a = a + latent_part(zg_[l], z_g);
      h = at::relu(norms_[l]->forward(a));
    }
    at::Tensor out = head_->forward(h);
    out = out.unflatten(-1, {joints_, 6});
    // Centred on the identity rotation so the initial output is well conditioned.
    at::Tensor identity = at::tensor({1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f}, out.options());
    return out + identity;
  }
  // A latent's projection [B, n] -> [B, 1, W] (bias-free). One window (B = 1,
  // every latent solve) takes a matrix-vector product: as a [1, n] x [n, W]
  // matrix product BLAS repacks the whole weight matrix on every call, which
  // cost about as much as the product itself (perf, 30-frame gaps).
  static at::Tensor latent_part(torch::nn::Linear& linear, const at::Tensor& z) {
    if (z.size(0) == 1) return at::mv(linear->weight, z.select(0, 0)).view({1, 1, -1});
    return linear->forward(z).unsqueeze(1);
  }
  // One window with frozen weights and constant times (every latent solve):
  // FrozenDecoderFunction, one autograd node.
  bool frozen_path_applies(const at::Tensor& pe, const at::Tensor& z_l, const at::Tensor& z_g) const {
    if (pe.size(0) != 1 || z_l.size(0) != 1 || z_g.size(0) != 1 || pe.requires_grad()) return false;
    if (pe.scalar_type() != at::kFloat || z_l.scalar_type() != at::kFloat || z_g.scalar_type() != at::kFloat)
      return false;
    if (!pe.device().is_cpu() || !z_l.device().is_cpu() || !z_g.device().is_cpu()) return false;
    return all_frozen(*this);
  }
  at::Tensor frozen_forward(const at::Tensor& pe, const at::Tensor& z_l, const at::Tensor& z_g);
  NemfConfig config_;
  int joints_;
  std::vector<torch::nn::Linear> pe_, zl_, hidden_, zg_;
  std::vector<torch::nn::LayerNorm> norms_;
  torch::nn::Linear head_{nullptr};
};
TORCH_MODULE(Decoder);

// The decoder of one window with frozen weights as a single autograd node with
// a hand-written backward (gradients of z_l and z_g only). A solve evaluates
// the decoder 50-100 times; as separate operators each layer recorded about ten
// autograd nodes, and their bookkeeping cost more than the arithmetic at the
// few key frames of a keys-only evaluation. The arithmetic is the same
// operators' (matrix products, ATen's layer norm), so values agree with the
// module path to rounding.
//
// Rows are independent until the latent gradients sum over them, so a dense
// window runs as two halves on two threads when there are two (num_chunks).
class FrozenDecoderFunction : public torch::autograd::Function<FrozenDecoderFunction> {
 public:
  // pe [S, 2F], z_l [zl], z_g [zg] -> 6D [S, J * 6].
  static torch::autograd::variable_list forward(torch::autograd::AutogradContext* ctx, const at::Tensor& pe,
                                                const at::Tensor& z_l, const at::Tensor& z_g, DecoderImpl* d) {
    const NemfConfig& c = d->config_;
    const int L = c.decoder_layers;
    const int64_t W = c.decoder_width, S = pe.size(0), chunks = num_chunks(S);
    std::vector<at::Tensor> bias(L);  // what the latents (and the time features' bias) add to every row
    for (int l = 0; l < L; ++l) {
      bias[l] = at::addmv(d->pe_[l]->bias, d->zl_[l]->weight, z_l);
      if (d->zg_[l]) bias[l].addmv_(d->zg_[l]->weight, z_g);
    }
    const at::Tensor identity =
        at::tensor({1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f}, pe.options()).repeat({d->joints_});
    const at::Tensor head_bias = d->head_->bias + identity;
    // saved: z_l, z_g, the weights the backward needs (kWeights per layer, then
    // the head's), then per chunk and layer a, mean, rstd and the layer's output.
    // The graph holds the weights, not the module: it may outlive the model.
    std::vector<at::Tensor> saved{z_l, z_g};
    for (int l = 0; l < L; ++l) {
      saved.push_back(d->zl_[l]->weight);
      saved.push_back(d->hidden_[l] ? d->hidden_[l]->weight : at::Tensor());
      saved.push_back(d->zg_[l] ? d->zg_[l]->weight : at::Tensor());
      saved.push_back(d->norms_[l]->weight);
      saved.push_back(d->norms_[l]->bias);
    }
    saved.push_back(d->head_->weight);
    const size_t first = saved.size();
    saved.resize(first + 4 * chunks * L);
    std::vector<at::Tensor> out(chunks);
    for_each_chunk(S, chunks, [&](int64_t k, int64_t r0, int64_t rows) {
      const at::Tensor x = pe.narrow(0, r0, rows);
      at::Tensor h;
      for (int l = 0; l < L; ++l) {
        at::Tensor a = at::addmm(bias[l], x, d->pe_[l]->weight.t());
        if (d->hidden_[l]) a.addmm_(h, d->hidden_[l]->weight.t());
        torch::nn::LayerNorm& norm = d->norms_[l];
        auto ln = at::native_layer_norm(a, {W}, norm->weight, norm->bias, norm->options.eps());
        h = at::relu(std::get<0>(ln));
        const size_t i = first + 4 * (k * L + l);
        saved[i] = a;
        saved[i + 1] = std::get<1>(ln);  // mean
        saved[i + 2] = std::get<2>(ln);  // rstd
        saved[i + 3] = h;
      }
      out[k] = at::addmm(head_bias, h, d->head_->weight.t());
    });
    ctx->save_for_backward(saved);
    ctx->saved_data["layers"] = static_cast<int64_t>(L);
    return {chunks == 1 ? out[0] : at::cat(out)};
  }

  static torch::autograd::variable_list backward(torch::autograd::AutogradContext* ctx,
                                                 torch::autograd::variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const int L = static_cast<int>(ctx->saved_data["layers"].toInt());
    auto weight = [&](int l, int which) -> const at::Tensor& { return saved[2 + kWeights * l + which]; };
    const at::Tensor& head = saved[2 + kWeights * L];
    const size_t first = 3 + kWeights * L;
    const int64_t chunks = (static_cast<int64_t>(saved.size()) - static_cast<int64_t>(first)) / (4 * L);
    const int64_t W = head.size(1);
    const at::Tensor& z_l = saved[0];
    const at::Tensor& z_g = saved[1];
    at::Tensor g_zl = at::zeros_like(z_l), g_zg = at::zeros_like(z_g);
    if (!grads[0].defined()) return {at::Tensor(), g_zl, g_zg, at::Tensor()};
    const at::Tensor g_out = grads[0].contiguous();
    const int64_t S = g_out.size(0);
    std::vector<at::Tensor> columns(chunks * L);  // per chunk and layer: d energy / d a, summed over rows
    for_each_chunk(S, chunks, [&](int64_t k, int64_t r0, int64_t rows) {
      at::Tensor g = at::mm(g_out.narrow(0, r0, rows), head);  // d / d (last layer's output)
      for (int l = L - 1; l >= 0; --l) {
        const size_t i = first + 4 * (k * L + l);
        const at::Tensor g_norm = at::threshold_backward(g, saved[i + 3], 0);
        const at::Tensor g_a = std::get<0>(at::native_layer_norm_backward(
            g_norm, saved[i], {W}, saved[i + 1], saved[i + 2], weight(l, 3), weight(l, 4), {true, false, false}));
        columns[k * L + l] = g_a.sum(0);
        if (l > 0) g = at::mm(g_a, weight(l, 1));
      }
    });
    for (int l = 0; l < L; ++l) {
      at::Tensor column = columns[l];
      for (int64_t k = 1; k < chunks; ++k) column = column + columns[k * L + l];
      g_zl.addmv_(weight(l, 0).t(), column);
      if (weight(l, 2).defined()) g_zg.addmv_(weight(l, 2).t(), column);
    }
    return {at::Tensor(), g_zl, g_zg, at::Tensor()};
  }

 private:
  // Saved weights per layer: z_l's, the hidden layer's, z_g's, the norm's weight and bias.
  static constexpr int kWeights = 5;
};

at::Tensor DecoderImpl::frozen_forward(const at::Tensor& pe, const at::Tensor& z_l, const at::Tensor& z_g) {
  const int64_t S = pe.size(1);
  at::Tensor out = FrozenDecoderFunction::apply(pe.reshape({S, pe.size(2)}).contiguous(), z_l.reshape({config_.zl}),
                                                z_g.reshape({config_.zg}), this)[0];
  return out.view({1, S, joints_, 6});
}

struct GlobalPredictorImpl : torch::nn::Module {
  GlobalPredictorImpl(const NemfConfig& c, int joints, int feet) : pad_(c.gmp_kernel / 2) {
    const int W = c.gmp_width;
    input_ = register_module("input", torch::nn::Conv1d(torch::nn::Conv1dOptions(joints * 3 + 6, W, c.gmp_kernel)));
    for (int i = 0; i < c.gmp_blocks; ++i) {
      blocks_.push_back(register_module("block" + std::to_string(i),
                                        torch::nn::Conv1d(torch::nn::Conv1dOptions(W, W, c.gmp_kernel))));
    }
    output_ = register_module("output", torch::nn::Conv1d(torch::nn::Conv1dOptions(W, 4 + feet, 1)));
  }
  at::Tensor pad(const at::Tensor& x) const { return at::replication_pad1d(x, {pad_, pad_}); }
  at::Tensor forward(const at::Tensor& x) {  // [B, C, T] -> [B, 4 + F, T]
    if (x.size(0) == 1 && x.scalar_type() == at::kFloat && x.device().is_cpu() && all_frozen(*this)) {
      return frozen_forward(x);
    }
    at::Tensor h = lrelu(input_->forward(pad(x)));
    for (auto& b : blocks_) h = h + lrelu(b->forward(pad(h)));
    return output_->forward(h);
  }
  at::Tensor frozen_forward(const at::Tensor& x);  // FrozenGmpFunction
  int pad_;
  torch::nn::Conv1d input_{nullptr}, output_{nullptr};
  std::vector<torch::nn::Conv1d> blocks_;
};
TORCH_MODULE(GlobalPredictor);

// The GMP of one window with frozen weights as a single autograd node with a
// hand-written backward (the gradient of its input only), like the decoder's.
// A dense window runs as two halves of its frames on two threads when there
// are two: each half also computes the frames within the stack's receptive
// field of it (a halo of pad x convolutions), replication-padding only at the
// window's true ends, so each half's outputs are exactly the whole window's.
class FrozenGmpFunction : public torch::autograd::Function<FrozenGmpFunction> {
 public:
  // One padded convolution's input range [first, first + length) of the window
  // and the padding it gets on each side (only at the window's ends).
  struct Span {
    int64_t first, length, left, right;
  };

  // x [1, C, T] -> [1, 4 + F, T].
  static torch::autograd::variable_list forward(torch::autograd::AutogradContext* ctx, const at::Tensor& x,
                                                GlobalPredictorImpl* g) {
    const int64_t T = x.size(2), chunks = num_chunks(T), R = g->pad_;
    const int64_t layers = 1 + static_cast<int64_t>(g->blocks_.size());
    // saved: x, the weights of the padded convolutions and of the output (the
    // graph holds them, not the module), then per chunk and padded convolution
    // its padded input and its pre-activation output.
    std::vector<at::Tensor> saved{x, g->input_->weight};
    for (auto& b : g->blocks_) saved.push_back(b->weight);
    saved.push_back(g->output_->weight);
    const size_t first = saved.size();
    saved.resize(first + 2 * chunks * layers);
    std::vector<at::Tensor> out(chunks);
    for_each_chunk(T, chunks, [&](int64_t k, int64_t r0, int64_t rows) {
      Span s = first_span(T, r0, rows, R, layers);
      at::Tensor h = x.narrow(2, s.first, s.length);
      for (int64_t l = 0; l < layers; ++l) {
        const at::Tensor p = at::replication_pad1d(h, {s.left, s.right});
        torch::nn::Conv1d& conv = l == 0 ? g->input_ : g->blocks_[l - 1];
        const at::Tensor y = at::conv1d(p, conv->weight, conv->bias);
        const Span next = next_span(T, s, R);
        h = l == 0 ? lrelu(y) : h.narrow(2, next.first - s.first, next.length) + lrelu(y);
        saved[first + 2 * (k * layers + l)] = p;
        saved[first + 2 * (k * layers + l) + 1] = y;
        s = next;
      }
      out[k] = at::conv1d(h.narrow(2, r0 - s.first, rows), g->output_->weight, g->output_->bias);
    });
    ctx->save_for_backward(saved);
    ctx->saved_data["pad"] = R;
    ctx->saved_data["layers"] = layers;
    ctx->saved_data["chunks"] = chunks;
    return {chunks == 1 ? out[0] : at::cat(out, 2)};
  }

  static torch::autograd::variable_list backward(torch::autograd::AutogradContext* ctx,
                                                 torch::autograd::variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const int64_t R = ctx->saved_data["pad"].toInt(), layers = ctx->saved_data["layers"].toInt();
    const size_t first = 2 + layers;
    const at::Tensor& x = saved[0];
    if (!grads[0].defined()) return {at::zeros_like(x), at::Tensor()};
    const at::Tensor g_out = grads[0].contiguous();
    const int64_t T = x.size(2), chunks = ctx->saved_data["chunks"].toInt();
    std::vector<at::Tensor> g_x(chunks);  // over each chunk's first span
    for_each_chunk(T, chunks, [&](int64_t k, int64_t r0, int64_t rows) {
      std::vector<Span> spans{first_span(T, r0, rows, R, layers)};
      for (int64_t l = 0; l < layers; ++l) spans.push_back(next_span(T, spans.back(), R));
      const Span& last = spans.back();
      const at::Tensor w_out = saved[1 + layers].squeeze(-1);  // [4 + F, W]
      at::Tensor g_h = at::zeros({1, w_out.size(1), last.length}, g_out.options());
      g_h.narrow(2, r0 - last.first, rows).copy_(at::matmul(w_out.t(), g_out.narrow(2, r0, rows)));
      for (int64_t l = layers - 1; l >= 0; --l) {
        const Span &in = spans[l], &outs = spans[l + 1];
        const at::Tensor &p = saved[first + 2 * (k * layers + l)], &y = saved[first + 2 * (k * layers + l) + 1];
        const at::Tensor& weight = saved[1 + l];
        const at::Tensor g_y = at::leaky_relu_backward(g_h, y, 0.2, false);
        const at::Tensor g_p = std::get<0>(at::convolution_backward(
            g_y, p, weight, c10::nullopt, {1}, {0}, {1}, false, {0}, 1, {true, false, false}));
        at::Tensor g_in = at::replication_pad1d_backward(g_p, p.narrow(2, in.left, in.length), {in.left, in.right});
        if (l > 0) g_in.narrow(2, outs.first - in.first, outs.length).add_(g_h);  // the residual path
        g_h = g_in;
      }
      g_x[k] = g_h;
    });
    at::Tensor g_input = at::zeros_like(x);
    for (int64_t k = 0; k < chunks; ++k) {
      const auto [r0, rows] = chunk_rows(T, chunks, k);
      const Span s = first_span(T, r0, rows, R, layers);
      g_input.narrow(2, s.first, s.length).add_(g_x[k]);
    }
    return {g_input, at::Tensor()};
  }

 private:
  // The input frames a chunk [r0, r0 + rows) needs: R x layers more on each
  // side, within the window; padded by R where it reaches the window's ends.
  static Span first_span(int64_t T, int64_t r0, int64_t rows, int64_t R, int64_t layers) {
    const int64_t first = std::max<int64_t>(0, r0 - R * layers), end = std::min(T, r0 + rows + R * layers);
    return {first, end - first, first == 0 ? R : 0, end == T ? R : 0};
  }
  // The output range of a padded convolution over span s, padded as the next one's input.
  static Span next_span(int64_t T, const Span& s, int64_t R) {
    const int64_t first = s.first + R - s.left, end = s.first + s.length - R + s.right;
    return {first, end - first, first == 0 ? R : 0, end == T ? R : 0};
  }
};

at::Tensor GlobalPredictorImpl::frozen_forward(const at::Tensor& x) {
  return FrozenGmpFunction::apply(x.contiguous(), this)[0];
}

struct NemfNetImpl : torch::nn::Module {
  NemfNetImpl(const NemfConfig& c, const RigInfo& rig) {
    local = register_module("local_encoder", LocalEncoder(c, rig.skeleton.parents));
    global = register_module("global_encoder", GlobalEncoder(c));
    decoder = register_module("decoder", Decoder(c, rig.num_joints()));
    gmp = register_module("gmp", GlobalPredictor(c, rig.num_joints(), rig.num_feet()));
    if (c.steering_gmp) {
      steering_gmp = register_module("steering_gmp", GlobalPredictor(c, rig.num_joints(), rig.num_feet()));
    }
  }
  LocalEncoder local{nullptr};
  GlobalEncoder global{nullptr};
  Decoder decoder{nullptr};
  GlobalPredictor gmp{nullptr};
  GlobalPredictor steering_gmp{nullptr};
};
TORCH_MODULE(NemfNet);

at::Tensor ones_like_stats(int64_t n) { return at::ones({n}); }

}  // namespace

at::Tensor time_encoding(const at::Tensor& frames, int window, int frequencies) {
  at::Tensor t = frames.to(at::kFloat) / static_cast<double>(window) * 2.0 - 1.0;
  at::Tensor freq = at::pow(2.0, at::arange(frequencies, at::kFloat));
  at::Tensor a = t.unsqueeze(-1) * freq;
  return at::cat({at::sin(a), at::cos(a)}, -1);
}

struct NemfModel::Impl {
  Impl(const NemfConfig& c, const RigInfo& r) : config(c), rig(r), net(c, r) {
    const int J = r.num_joints();
    stats.feature_mean = at::zeros({J * kFeaturesPerJoint});
    stats.feature_std = ones_like_stats(J * kFeaturesPerJoint);
    stats.root_mean = at::zeros({6});
    stats.root_std = ones_like_stats(6);
    stats.gmp_in_mean = at::zeros({J * 3 + 6});
    stats.gmp_in_std = ones_like_stats(J * 3 + 6);
    stats.gmp_out_mean = at::zeros({4});
    stats.gmp_out_std = ones_like_stats(4);
  }
  NemfConfig config;
  RigInfo rig;
  NemfStats stats;
  NemfNet net;
};

NemfModel::NemfModel(const NemfConfig& config, const RigInfo& rig) {
  std::string problem = config.validate();
  if (!problem.empty()) throw InputError("invalid prior configuration: " + problem);
  rig.skeleton.validate();
  impl_ = std::make_unique<Impl>(config, rig);
}
NemfModel::~NemfModel() = default;
NemfModel::NemfModel(NemfModel&&) noexcept = default;
NemfModel& NemfModel::operator=(NemfModel&&) noexcept = default;

const NemfConfig& NemfModel::config() const { return impl_->config; }
const RigInfo& NemfModel::rig() const { return impl_->rig; }
NemfStats& NemfModel::stats() { return impl_->stats; }
const NemfStats& NemfModel::stats() const { return impl_->stats; }

NemfLatent NemfModel::encode(const at::Tensor& local_rotations, const at::Tensor& mask) const {
  const int64_t T = local_rotations.size(1), J = impl_->rig.num_joints();
  if (local_rotations.dim() != 5 || T < 2 || T > impl_->config.window || local_rotations.size(2) != J) {
    throw InputError("encode: expected [B, T, " + std::to_string(J) + ", 3, 3] with 2 <= T <= " +
                     std::to_string(impl_->config.window));
  }
  at::Tensor root6d;
  at::Tensor features = local_features(local_rotations, impl_->rig, impl_->config.fps, &root6d);
  return encode_features(features.flatten(2), root6d, mask);
}

NemfLatent NemfModel::encode_features(const at::Tensor& features, const at::Tensor& root6d,
                                      const at::Tensor& mask) const {
  const NemfConfig& c = impl_->config;
  const int64_t B = features.size(0), T = features.size(1), J = impl_->rig.num_joints();
  if (T < 1 || T > c.window || features.size(2) != J * kFeaturesPerJoint) {
    throw InputError("encode: expected features [B, T, " + std::to_string(J * kFeaturesPerJoint) + "] with T <= " +
                     std::to_string(c.window));
  }
  const NemfStats& s = impl_->stats;
  at::Tensor m = mask.to(features.options()).unsqueeze(-1);  // [B, T, 1]
  at::Tensor f = (features - s.feature_mean) / s.feature_std * m;
  at::Tensor r = (root6d - s.root_mean) / s.root_std * m;
  if (T < c.window) {
    f = at::cat({f, at::zeros({B, c.window - T, f.size(2)}, f.options())}, 1);
    r = at::cat({r, at::zeros({B, c.window - T, 6}, r.options())}, 1);
    m = at::cat({m, at::zeros({B, c.window - T, 1}, m.options())}, 1);
  }
  // Per joint: its 15 features then the mask, channels-first for the convolutions.
  at::Tensor local_in = at::cat({f.unflatten(2, {J, kFeaturesPerJoint}), m.unsqueeze(2).expand({B, c.window, J, 1})}, -1)
                            .flatten(2)
                            .transpose(1, 2);
  at::Tensor global_in = at::cat({r, m}, -1).transpose(1, 2);
  at::Tensor l = impl_->net->local->forward(local_in);
  at::Tensor g = impl_->net->global->forward(global_in);
  NemfLatent z;
  z.mu_l = l.narrow(1, 0, c.zl);
  z.logvar_l = l.narrow(1, c.zl, c.zl);
  z.mu_g = g.narrow(1, 0, c.zg);
  z.logvar_g = g.narrow(1, c.zg, c.zg);
  return z;
}

at::Tensor NemfModel::decode(const at::Tensor& frames, const at::Tensor& z_l, const at::Tensor& z_g) const {
  return torch_rot::sixd_to_matrix(decode_sixd(frames, z_l, z_g));
}

at::Tensor NemfModel::decode_sixd(const at::Tensor& frames, const at::Tensor& z_l, const at::Tensor& z_g) const {
  const NemfConfig& c = impl_->config;
  at::Tensor pe = time_encoding(frames, c.window, c.pe_frequencies).to(z_l.options());
  if (pe.dim() == 2) pe = pe.unsqueeze(0);
  return impl_->net->decoder->forward(pe, z_l, z_g);
}

GmpOutput NemfModel::predict_global(const at::Tensor& local_rotations, GmpUse use) const {
  return predict_global_from_inputs(gmp_inputs(local_rotations, impl_->rig), use);
}

bool NemfModel::has_steering_gmp() const { return !impl_->net->steering_gmp.is_empty(); }

GmpOutput NemfModel::predict_global_from_inputs(const at::Tensor& inputs, GmpUse use) const {
  const RigInfo& rig = impl_->rig;
  const NemfStats& s = impl_->stats;
  GlobalPredictor& gmp = use == GmpUse::Steering && has_steering_gmp() ? impl_->net->steering_gmp : impl_->net->gmp;
  at::Tensor x = (inputs - s.gmp_in_mean) / s.gmp_in_std;
  at::Tensor y = gmp->forward(x.transpose(1, 2)).transpose(1, 2);  // [B, T, 4 + F]
  at::Tensor out = y.narrow(-1, 0, 4) * s.gmp_out_std + s.gmp_out_mean;
  GmpOutput g;
  g.velocity = out.narrow(-1, 0, 3);
  g.height = out.narrow(-1, 3, 1);
  g.contact_logits = y.narrow(-1, 4, rig.num_feet());
  return g;
}

at::Tensor NemfModel::root_positions(const at::Tensor& local_rotations, const GmpOutput& gmp,
                                     const at::Tensor& start_xz) const {
  at::Tensor h = heading_rotation(local_rotations.select(-3, 0), impl_->rig.root_forward);
  return integrate_root(gmp.velocity, gmp.height, h, impl_->config.fps, start_xz);
}

std::vector<std::pair<std::string, at::Tensor>> NemfModel::named_parameters() const {
  return named_parameters_of(*impl_->net);
}

std::vector<at::Tensor> NemfModel::parameters() const { return impl_->net->parameters(true); }

std::vector<at::Tensor> NemfModel::vae_parameters() const {
  std::vector<at::Tensor> out;
  for (const auto& item : impl_->net->named_parameters(true)) {
    const std::string& k = item.key();
    if (k.rfind("gmp.", 0) != 0 && k.rfind("steering_gmp.", 0) != 0) out.push_back(item.value());
  }
  return out;
}

std::vector<at::Tensor> NemfModel::gmp_parameters() const { return impl_->net->gmp->parameters(true); }

int64_t NemfModel::num_parameters() const {
  int64_t n = 0;
  for (auto& p : parameters()) n += p.numel();
  return n;
}

void NemfModel::train(bool on) { impl_->net->train(on); }

void NemfModel::set_requires_grad(bool on) {
  for (auto& p : parameters()) p.set_requires_grad(on);
  impl_->net->local->set_frozen(!on);
}

}  // namespace mf
