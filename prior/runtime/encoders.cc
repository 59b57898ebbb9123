#include "prior/runtime/encoders.h"

#include <algorithm>
#include <string>

#include "prior/motion/errors.h"

namespace mf::runtime {

namespace {

constexpr float kSlope = 0.2f;           // nemf.cc's lrelu
constexpr float kGroupNormEps = 1e-5f;   // torch::nn::GroupNorm's default
constexpr int kLocalInputsPerJoint = 16; // 15 features and the mask
constexpr int kMixChannels = 256;

// The skeleton convolution's mask (SkeletonConvImpl in nemf.cc): output joint j
// reads input joint i only when they are the same joint, parent or child.
// Trained weights are already zero elsewhere; the frozen libtorch model masks
// them once as well.
void mask_skeleton_conv(const std::vector<int>& parents, Conv1dWeights* conv) {
  const int J = static_cast<int>(parents.size());
  const int cin = conv->in() / J, cout = conv->out() / J;
  for (int j = 0; j < J; ++j)
    for (int i = 0; i < J; ++i) {
      if (i == j || parents[j] == i || parents[i] == j) continue;
      for (WeightMatrix& tap : conv->taps) tap.mutable_values().block(i * cin, j * cout, cin, cout).setZero();
    }
}

}  // namespace

NemfEncoders::NemfEncoders(const NemfConfig& config, const std::vector<int>& parents, WeightReader& weights)
    : joints_(static_cast<int>(parents.size())), window_(config.window) {
  const int J = joints_, positions = config.window / 16;
  int cin = kLocalInputsPerJoint;
  for (int i = 0; i < 4; ++i) {
    const int cout = config.encoder_channels * std::min(1 << i, 2);
    const std::string s = std::to_string(i);
    Stage stage{weights.conv("local_encoder.conv" + s, J * cout, J * cin, 4), {}, {}};
    mask_skeleton_conv(parents, &stage.conv);
    stage.conv.kernels = false;  // the encoders run once per solve: not worth packing
    stage.norm_weight = weights.vector("local_encoder.norm" + s + ".weight", J * cout);
    stage.norm_bias = weights.vector("local_encoder.norm" + s + ".bias", J * cout);
    local_.push_back(std::move(stage));
    cin = cout;
  }
  mix_ = weights.conv("local_encoder.mix", kMixChannels, J * cin, 1);
  mix_.kernels = false;
  local_head_ = weights.matrix("local_encoder.head.weight", 2 * config.zl, kMixChannels * positions);
  local_head_bias_ = weights.vector("local_encoder.head.bias", 2 * config.zl);
  const int channels[5] = {7, 64, 128, 128, 128};
  for (int i = 0; i < 4; ++i) {
    global_.push_back({weights.conv("global_encoder.conv" + std::to_string(i), channels[i + 1], channels[i], 4), {}, {}});
    global_.back().conv.kernels = false;
  }
  global_head_ = weights.matrix("global_encoder.head.weight", 2 * config.zg, channels[4] * positions);
  global_head_bias_ = weights.vector("global_encoder.head.bias", 2 * config.zg);
}

Eigen::VectorXf NemfEncoders::run(const std::vector<Stage>& stages, int groups, const Conv1dWeights* mix,
                                  const MatrixRXf& head, const RowVectorXf& head_bias, ConstMatrixRef input) {
  MatrixRXf x = input, padded, y;
  for (const Stage& stage : stages) {  // kernel 4, stride 2, zero padding 1
    padded.setZero(x.rows() + 2, x.cols());
    padded.middleRows(1, x.rows()) = x;
    conv1d(padded, stage.conv, 2, &y);
    if (stage.norm_weight.size()) group_norm_columns(y, groups, stage.norm_weight, stage.norm_bias, kGroupNormEps);
    leaky_relu(y, kSlope);
    x.swap(y);
  }
  if (mix) {
    conv1d(x, *mix, 1, &y);
    leaky_relu(y, kSlope);
    x.swap(y);
  }
  // libtorch flattens [C, T'] channels-first: x's column-major order.
  const Eigen::MatrixXf channels_first = x;
  const Eigen::Map<const Eigen::VectorXf> flat(channels_first.data(), channels_first.size());
  return head * flat + head_bias.transpose();
}

Eigen::VectorXf NemfEncoders::local(ConstMatrixRef input) const {
  if (input.rows() != window_ || input.cols() != joints_ * kLocalInputsPerJoint) {
    throw InputError("local encoder: expected [window, " + std::to_string(joints_ * kLocalInputsPerJoint) + "]");
  }
  return run(local_, joints_, &mix_, local_head_, local_head_bias_, input);
}

Eigen::VectorXf NemfEncoders::global(ConstMatrixRef input) const {
  if (input.rows() != window_ || input.cols() != 7) throw InputError("global encoder: expected [window, 7]");
  return run(global_, 1, nullptr, global_head_, global_head_bias_, input);
}

}  // namespace mf::runtime
