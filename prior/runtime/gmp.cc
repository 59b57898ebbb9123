#include "prior/runtime/gmp.h"

#include "prior/motion/errors.h"

namespace mf::runtime {

namespace {

constexpr float kSlope = 0.2f;  // nemf.cc's lrelu

}  // namespace

NemfGmpNetwork::NemfGmpNetwork(const NemfConfig& config, int joints, int feet, const std::string& prefix,
                               WeightReader& weights)
    : pad_(config.gmp_kernel / 2) {
  const int W = config.gmp_width, K = config.gmp_kernel;
  convs_.push_back(weights.conv(prefix + ".input", W, joints * 3 + 6, K));
  for (int i = 0; i < config.gmp_blocks; ++i) convs_.push_back(weights.conv(prefix + ".block" + std::to_string(i), W, W, K));
  output_ = weights.conv(prefix + ".output", 4 + feet, W, 1);
}

void NemfGmpNetwork::forward(ConstMatrixRef x, GmpWorkspace* ws, MatrixRXf* y) const {
  if (x.rows() < 1 || x.cols() != convs_.front().in()) {
    throw InputError("GMP: expected inputs [T, " + std::to_string(convs_.front().in()) + "] with T >= 1");
  }
  const size_t layers = convs_.size();
  ws->padded.resize(layers);
  ws->pre.resize(layers);
  for (size_t l = 0; l < layers; ++l) {
    replication_pad_rows(l == 0 ? x : ConstMatrixRef(ws->h), pad_, &ws->padded[l]);
    conv1d(ws->padded[l], convs_[l], 1, &ws->pre[l]);
    if (l == 0) {
      ws->h = ws->pre[0];
      leaky_relu(ws->h, kSlope);
    } else {
      ws->activated = ws->pre[l];
      leaky_relu(ws->activated, kSlope);
      ws->h += ws->activated;
    }
  }
  conv1d(ws->h, output_, 1, y);
}

void NemfGmpNetwork::input_gradient(GmpWorkspace* ws, ConstMatrixRef g_y, MatrixRXf* g_x) const {
  const Eigen::Index T = ws->h.rows();
  if (ws->pre.size() != convs_.size() || g_y.rows() != T || g_y.cols() != output_.out()) {
    throw InputError("GMP gradient: expected [" + std::to_string(T) + ", " + std::to_string(output_.out()) +
                     "] at the workspace's last forward");
  }
  ws->g_h.resize(T, output_.in());
  gemm(g_y, false, output_.taps[0], true, ws->g_h, 0.0f);
  for (size_t l = convs_.size(); l-- > 0;) {
    ws->g_in = ws->g_h;  // d / d (the block's output before the leaky ReLU)
    leaky_relu_gradient(ws->pre[l], kSlope, ws->g_in);
    ws->g_padded.setZero(T + 2 * pad_, convs_[l].in());
    conv1d_input_gradient(ws->g_in, convs_[l], 1, ws->g_padded);
    if (l == 0) {
      replication_pad_rows_gradient(ws->g_padded, pad_, g_x);
    } else {
      replication_pad_rows_gradient(ws->g_padded, pad_, &ws->g_in);
      ws->g_h += ws->g_in;  // the residual path
    }
  }
}

}  // namespace mf::runtime
