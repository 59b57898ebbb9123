// The Eigen runtime (prior/runtime/nemf_runtime.h) against the libtorch
// prior (prior/model/nemf.h), both loaded from the shipped model file: the
// decoder, its gradient with respect to the latents, the GMPs and their input
// gradients, and the encoders, on random inputs and on a real window (the
// sample walk retargeted to the model's rig). Differences are measured as
// max |runtime - libtorch| / max |libtorch| over the compared values:
// outputs within 1e-5, gradients within 1e-4 (issue 56's bounds). The
// runtime's gradients are also checked against central differences of the
// same network in float64 (directional derivatives).
#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>

#include "prior/model/model_file.h"
#include "prior/model/representation.h"
#include "prior/motion/errors.h"
#include "prior/motion/rotations_torch.h"
#include "prior/runtime/local_features.h"
#include "prior/runtime/nemf_runtime.h"
#include "prior/util/threads.h"
#include "tests/runtime_test_util.h"

namespace mf {
namespace {

using test::float64_model;
using test::MatrixRXf;
using test::normal_matrix;
using test::relative_difference;
using test::relative_vector_difference;
using test::to_matrix;
using test::to_tensor;
using test::to_vector;

using test::kGradientTolerance;
using test::kOutputTolerance;

const test::BothModels& models() { return test::shipped_models(); }

// The shipped prior with its weights unfrozen: decode and the GMP take the
// module path, whose gradients are libtorch's own autograd.
const NemfModel& autograd_model() {
  static const NemfModel m = [] {
    NemfModel model = load_nemf(test::shipped_model_path());
    model.set_requires_grad(true);
    return model;
  }();
  return m;
}

using test::kDifferenceStep;

// The sample walk on the model's rig as one canonical window of its 61 frames.
const WindowTensors& real_window() {
  static const WindowTensors w = [] {
    const Motion& on_model = test::walk_on_model_rig();
    return window_tensors(on_model, 0, on_model.num_frames(), models().frozen.rig(), 0);
  }();
  return w;
}

// Decodes at `frames` both ways and compares the 6D outputs, then the
// latents' gradients of <g, output> for a random g: against the frozen
// model's hand-written backward and against libtorch's autograd.
void expect_decoders_agree(const Eigen::VectorXd& frames, const Eigen::VectorXf& z_l, const Eigen::VectorXf& z_g,
                           uint32_t seed) {
  ScopedComputeThreads one_thread(1);
  const test::BothModels& m = models();
  const int64_t S = frames.size(), J6 = m.runtime.rig().num_joints() * 6;
  runtime::DecoderWorkspace ws;
  MatrixRXf out;
  m.runtime.decode(frames, z_l, z_g, &ws, &out);
  std::mt19937 rng(seed);
  const MatrixRXf g = normal_matrix(S, J6, rng);
  Eigen::VectorXf g_zl, g_zg;
  m.runtime.decode_vjp(&ws, g, &g_zl, &g_zg);
  const at::Tensor t_frames = at::from_blob(const_cast<double*>(frames.data()), {S}, at::kDouble).clone();
  for (const NemfModel* torch_model : {&m.frozen, &autograd_model()}) {
    const at::Tensor t_zl = to_tensor(z_l.transpose()).requires_grad_(true);
    const at::Tensor t_zg = to_tensor(z_g.transpose()).requires_grad_(true);
    const at::Tensor t_out = torch_model->decode_sixd(t_frames, t_zl, t_zg).reshape({S, J6});
    (t_out * to_tensor(g)).sum().backward();
    const double output = relative_difference(out, to_matrix(t_out));
    const double grad_l = relative_vector_difference(g_zl, to_vector(t_zl.grad()));
    const double grad_g = relative_vector_difference(g_zg, to_vector(t_zg.grad()));
    EXPECT_LT(output, kOutputTolerance);
    EXPECT_LT(grad_l, kGradientTolerance);
    EXPECT_LT(grad_g, kGradientTolerance);
    std::printf("decoder S=%ld (%s): output %.2e, d z_l %.2e, d z_g %.2e\n", static_cast<long>(S),
                torch_model == &m.frozen ? "frozen" : "autograd", output, grad_l, grad_g);
  }
}

// The runtime decoder's latent gradient of <g, output> against central
// differences of the float64 network along unit directions of (z_l, z_g):
// the gradient's own and two random ones. The bound, 1e-4 of the gradient's
// norm (the largest a directional derivative can be), is what the float32
// forward's rounding leaves.
void expect_decoder_gradient_matches_differences(const Eigen::VectorXd& frames, const Eigen::VectorXf& z_l,
                                                 const Eigen::VectorXf& z_g, uint32_t seed) {
  const runtime::NemfRuntime& rt = models().runtime;
  const int64_t S = frames.size(), J6 = rt.rig().num_joints() * 6, zl = z_l.size();
  std::mt19937 rng(seed);
  const MatrixRXf g = normal_matrix(S, J6, rng);
  runtime::DecoderWorkspace ws;
  MatrixRXf out;
  Eigen::VectorXf g_zl, g_zg;
  rt.decode(frames, z_l, z_g, &ws, &out);
  rt.decode_vjp(&ws, g, &g_zl, &g_zg);
  Eigen::VectorXd grad(zl + z_g.size()), z(zl + z_g.size());
  grad << g_zl.cast<double>(), g_zg.cast<double>();
  z << z_l.cast<double>(), z_g.cast<double>();
  const at::Tensor t_frames = at::from_blob(const_cast<double*>(frames.data()), {S}, at::kDouble).clone();
  const at::Tensor t_g = to_tensor(g).to(at::kDouble);
  auto energy = [&](const Eigen::VectorXd& point) {
    at::NoGradGuard no_grad;
    const at::Tensor p = at::from_blob(const_cast<double*>(point.data()), {1, point.size()}, at::kDouble).clone();
    const at::Tensor o = float64_model().decode_sixd(t_frames, p.narrow(1, 0, zl), p.narrow(1, zl, p.size(1) - zl));
    return (o.reshape({S, J6}) * t_g).sum().item<double>();
  };
  std::normal_distribution<double> n;
  for (int d = 0; d < 3; ++d) {
    Eigen::VectorXd v = grad;
    if (d > 0) v = v.unaryExpr([&](double) { return n(rng); });
    v.normalize();
    const double numeric =
        (energy(z + kDifferenceStep * v) - energy(z - kDifferenceStep * v)) / (2 * kDifferenceStep);
    EXPECT_NEAR(grad.dot(v), numeric, 1e-4 * grad.norm()) << "direction " << d;
    std::printf("decoder S=%ld, direction %d: runtime %.6e, differences %.6e, |diff| / |grad| %.2e\n",
                static_cast<long>(S), d, grad.dot(v), numeric, std::abs(grad.dot(v) - numeric) / grad.norm());
  }
}

TEST(RuntimeEquivalence, DecoderGradientMatchesFiniteDifferences) {
  std::mt19937 rng(4);
  const NemfConfig& c = models().runtime.config();
  for (int S : {4, 30}) {
    Eigen::VectorXd frames = Eigen::VectorXd::LinSpaced(S, 2.5, c.window - 3.5);
    const MatrixRXf z_l = normal_matrix(c.zl, 1, rng), z_g = normal_matrix(c.zg, 1, rng);
    expect_decoder_gradient_matches_differences(frames, z_l, z_g, 200 + S);
  }
}

TEST(RuntimeEquivalence, DecoderOnRandomLatentsAndTimes) {
  std::mt19937 rng(1);
  const NemfConfig& c = models().runtime.config();
  std::uniform_real_distribution<double> frame(0.0, c.window - 1);
  for (int S : {1, 30, 128}) {
    Eigen::VectorXd frames(S);
    for (int s = 0; s < S; ++s) frames[s] = frame(rng);
    const MatrixRXf z_l = normal_matrix(c.zl, 1, rng), z_g = normal_matrix(c.zg, 1, rng);
    expect_decoders_agree(frames, z_l, z_g, 100 + S);
  }
}

TEST(RuntimeEquivalence, EncodersAndDecoderOnARealWindow) {
  ScopedComputeThreads one_thread(1);
  const test::BothModels& m = models();
  const WindowTensors& w = real_window();
  const int64_t T = w.local_rotations.size(1);
  at::Tensor root6d;
  const at::Tensor features = local_features(w.local_rotations, m.frozen.rig(), m.frozen.config().fps, &root6d);
  // Two frames missing inside the window as well as the frames after it.
  at::Tensor mask = at::ones({1, T});
  mask[0][20] = 0.0f;
  mask[0][21] = 0.0f;
  const NemfLatent t = m.frozen.encode_features(features.flatten(2), root6d, mask);
  const runtime::LatentGaussians r =
      m.runtime.encode_features(to_matrix(features[0]), to_matrix(root6d[0]), to_vector(mask[0]));
  const double diffs[4] = {relative_vector_difference(r.mu_l, to_vector(t.mu_l)),
                           relative_vector_difference(r.logvar_l, to_vector(t.logvar_l)),
                           relative_vector_difference(r.mu_g, to_vector(t.mu_g)),
                           relative_vector_difference(r.logvar_g, to_vector(t.logvar_g))};
  for (double d : diffs) EXPECT_LT(d, kOutputTolerance);
  std::printf("encoders T=%ld: mu_l %.2e, logvar_l %.2e, mu_g %.2e, logvar_g %.2e\n", static_cast<long>(T), diffs[0],
              diffs[1], diffs[2], diffs[3]);
  // The decoder at the walk's own latents, on its frames.
  expect_decoders_agree(Eigen::VectorXd::LinSpaced(T, 0.0, T - 1.0), to_vector(t.mu_l), to_vector(t.mu_g), 5);
}

// The encoders' input on Eigen (prior/runtime/local_features.h) against
// local_features() on the sample walk and on random rotations (one frame,
// two, a full window), and the walk's codes on the Eigen features against
// libtorch's encode().
TEST(RuntimeEquivalence, LocalFeaturesAndTheCodesOnThem) {
  ScopedComputeThreads one_thread(1);
  const test::BothModels& m = models();
  const runtime::Kinematics kinematics(m.runtime.rig().skeleton);
  const Eigen::Vector3f forward = m.runtime.rig().root_forward.cast<float>();
  const double fps = m.frozen.config().fps;
  const int J = m.runtime.rig().num_joints();
  at::manual_seed(9);
  std::vector<at::Tensor> windows = {real_window().local_rotations};
  for (int T : {1, 2, 128}) windows.push_back(torch_rot::sixd_to_matrix(at::randn({1, T, J, 6})));
  for (const at::Tensor& rotations : windows) {
    const int64_t T = rotations.size(1);
    at::Tensor root6d;
    const at::Tensor expected = local_features(rotations, m.frozen.rig(), fps, &root6d);
    MatrixRXf features, root;
    runtime::local_features(kinematics, to_matrix(rotations[0]), forward, fps, &features, &root);
    const double d_features = relative_difference(features, to_matrix(expected[0]));
    const double d_root = relative_difference(root, to_matrix(root6d[0]));
    std::printf("local features T=%ld: %.2e, root 6D %.2e\n", static_cast<long>(T), d_features, d_root);
    EXPECT_LT(d_features, kOutputTolerance);
    EXPECT_LT(d_root, kOutputTolerance);
  }
  const at::Tensor& walk = real_window().local_rotations;
  const int64_t T = walk.size(1);
  const NemfLatent t = m.frozen.encode(walk, at::ones({1, T}));
  MatrixRXf features, root;
  runtime::local_features(kinematics, to_matrix(walk[0]), forward, fps, &features, &root);
  const runtime::LatentGaussians r = m.runtime.encode_features(features, root, Eigen::VectorXf::Ones(T));
  EXPECT_LT(relative_vector_difference(r.mu_l, to_vector(t.mu_l)), kOutputTolerance);
  EXPECT_LT(relative_vector_difference(r.mu_g, to_vector(t.mu_g)), kOutputTolerance);
  const runtime::LatentGaussians direct = m.runtime.encode_rotations(to_matrix(walk[0]));
  EXPECT_EQ(direct.mu_l, r.mu_l);
  EXPECT_EQ(direct.mu_g, r.mu_g);
  EXPECT_THROW(m.runtime.encode_rotations(MatrixRXf::Zero(T, 9)), InputError);
}

// Both GMPs on `inputs` [T, J * 3 + 6]: outputs, and the input gradient of
// <g, outputs> for a random g against the frozen node's and autograd's.
void expect_gmps_agree(const MatrixRXf& inputs, uint32_t seed) {
  ScopedComputeThreads one_thread(1);
  const test::BothModels& m = models();
  const int64_t T = inputs.rows(), outputs = 4 + m.runtime.rig().num_feet();
  std::mt19937 rng(seed);
  const MatrixRXf g = normal_matrix(T, outputs, rng);
  for (GmpUse use : {GmpUse::Default, GmpUse::Steering}) {
    runtime::GmpWorkspace ws;
    MatrixRXf out, g_in;
    m.runtime.predict_global(inputs, use, &ws, &out);
    m.runtime.predict_global_vjp(&ws, use, g, &g_in);
    for (const NemfModel* torch_model : {&m.frozen, &autograd_model()}) {
      const at::Tensor x = to_tensor(inputs).unsqueeze(0).requires_grad_(true);
      const GmpOutput o = torch_model->predict_global_from_inputs(x, use);
      const at::Tensor t_out = at::cat({o.velocity, o.height, o.contact_logits}, -1)[0];
      (t_out * to_tensor(g)).sum().backward();
      const double output = relative_difference(out, to_matrix(t_out));
      const double grad = relative_difference(g_in, to_matrix(x.grad()[0]));
      EXPECT_LT(output, kOutputTolerance);
      EXPECT_LT(grad, kGradientTolerance);
      std::printf("GMP %s T=%ld (%s): output %.2e, d inputs %.2e\n", use == GmpUse::Steering ? "steering" : "default",
                  static_cast<long>(T), torch_model == &m.frozen ? "frozen" : "autograd", output, grad);
    }
  }
}

// The runtime GMPs' input gradients of <g, outputs> against central
// differences of the float64 networks along unit directions in normalised
// input units (each input channel moved by its standard deviation): the
// gradient's own and two random ones; bound 1e-4 of the gradient's norm in
// those units, as for the decoder.
void expect_gmp_gradients_match_differences(const MatrixRXf& inputs, uint32_t seed) {
  const runtime::NemfRuntime& rt = models().runtime;
  const int64_t T = inputs.rows(), C = inputs.cols(), outputs = 4 + rt.rig().num_feet();
  std::mt19937 rng(seed);
  const MatrixRXf g = normal_matrix(T, outputs, rng);
  const at::Tensor t_g = to_tensor(g).to(at::kDouble), t_x = to_tensor(inputs).to(at::kDouble).unsqueeze(0);
  const Eigen::ArrayXXd scale = rt.stats().gmp_in_std.cast<double>().array().replicate(T, 1);
  for (GmpUse use : {GmpUse::Default, GmpUse::Steering}) {
    runtime::GmpWorkspace ws;
    MatrixRXf out, g_x;
    rt.predict_global(inputs, use, &ws, &out);
    rt.predict_global_vjp(&ws, use, g, &g_x);
    const Eigen::ArrayXXd grad = g_x.cast<double>().array() * scale;  // in normalised units
    auto energy = [&](const Eigen::ArrayXXd& step) {
      at::NoGradGuard no_grad;
      const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> raw = step * scale;
      const at::Tensor x = t_x + at::from_blob(const_cast<double*>(raw.data()), {1, T, C}, at::kDouble);
      const GmpOutput o = float64_model().predict_global_from_inputs(x, use);
      return (at::cat({o.velocity, o.height, o.contact_logits}, -1)[0] * t_g).sum().item<double>();
    };
    std::normal_distribution<double> n;
    const double norm = std::sqrt(grad.square().sum());
    for (int d = 0; d < 3; ++d) {
      Eigen::ArrayXXd v = d == 0 ? grad : grad.unaryExpr([&](double) { return n(rng); });
      v /= std::sqrt(v.square().sum());
      const double analytic = (grad * v).sum();
      const double numeric = (energy(kDifferenceStep * v) - energy(-kDifferenceStep * v)) / (2 * kDifferenceStep);
      EXPECT_NEAR(analytic, numeric, 1e-4 * norm) << "direction " << d;
      std::printf("GMP %s T=%ld, direction %d: runtime %.6e, differences %.6e, |diff| / |grad| %.2e\n",
                  use == GmpUse::Steering ? "steering" : "default", static_cast<long>(T), d, analytic, numeric,
                  std::abs(analytic - numeric) / norm);
    }
  }
}

TEST(RuntimeEquivalence, GmpGradientsMatchFiniteDifferences) {
  const WindowTensors& w = real_window();
  expect_gmp_gradients_match_differences(to_matrix(gmp_inputs(w.local_rotations, models().frozen.rig())[0]), 31);
}

TEST(RuntimeEquivalence, GmpsOnARealWindow) {
  const WindowTensors& w = real_window();
  expect_gmps_agree(to_matrix(gmp_inputs(w.local_rotations, models().frozen.rig())[0]), 21);
}

TEST(RuntimeEquivalence, GmpsOnRandomInputs) {
  const runtime::NemfRuntimeStats& s = models().runtime.stats();
  std::mt19937 rng(2);
  for (int T : {9, 128}) {
    const MatrixRXf n = normal_matrix(T, s.gmp_in_mean.size(), rng);
    expect_gmps_agree(((n.array().rowwise() * s.gmp_in_std.array()).rowwise() + s.gmp_in_mean.array()).matrix(), T);
  }
}

}  // namespace
}  // namespace mf
