// Re-navigation's energy on the Eigen runtime (RenavRuntimeEnergy,
// tasks/renav/renav_runtime_energy.h) against the libtorch energy with
// autograd (evaluate_renav_energy(), tasks/reference/renav_energy.h), with the shipped
// model on windows of the sample walk re-navigated along a curved path (a
// first window, and a later one that shares frames with a previous
// solution), at the encoder's codes and at random ones: every term on its
// own and together, values within 1e-5 and gradients within 1e-4, relative
// (issue 56's bounds). Gradients are also checked against central
// differences of the float64 prior.
#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "prior/model/canonical_window.h"
#include "prior/motion/errors.h"
#include "prior/util/threads.h"
#include "tasks/reference/renav_energy.h"
#include "tasks/renav/renav.h"
#include "tasks/renav/renav_runtime_energy.h"
#include "tests/runtime_test_util.h"

// In mf::test, where the helpers of runtime_test_util.h are.
namespace mf::test {
namespace {

// A curve of `frames` points from the walk's first root position: 1.2 m/s,
// turning left at 0.5 rad/s.
std::vector<Eigen::Vector2d> curved_path(const Motion& walk, int frames, double fps) {
  std::vector<Eigen::Vector2d> p;
  const Eigen::Vector2d start(walk.root_positions[0].x(), walk.root_positions[0].z());
  const double speed = 1.2, rate = 0.5, radius = speed / rate;
  for (int f = 0; f < frames; ++f) {
    const double a = rate * f / fps;
    p.push_back(start + radius * Eigen::Vector2d(1.0 - std::cos(a), std::sin(a)));
  }
  return p;
}

struct NamedWindow {
  const char* name;
  RenavWindow window;
};

// The first window of the walk along the curve, and a later one that shares
// 15 frames with a previous solution (the walk itself).
const std::vector<NamedWindow>& windows() {
  static const std::vector<NamedWindow> w = [] {
    const runtime::NemfRuntime& model = shipped_models().runtime;
    const Motion& walk = walk_on_model_rig();
    const std::vector<Eigen::Vector2d> path = curved_path(walk, 90, model.config().fps);
    return std::vector<NamedWindow>{{"first window", make_renav_window(model, walk, 0, 61, path, 0, 61)},
                                    {"later window", make_renav_window(model, walk, 10, 45, path, 20, 60, &walk, 15)}};
  }();
  return w;
}

struct NamedWeights {
  std::string name;
  RenavWeights weights;
};

// Each term alone, the default weights, and every term at once.
std::vector<NamedWeights> weight_sets() {
  std::vector<NamedWeights> sets;
  const char* names[] = {"path", "joints", "heading", "foot_skating", "continuity"};
  for (int i = 0; i < 5; ++i) {
    RenavWeights w;
    double* fields[] = {&w.path, &w.joints, &w.heading, &w.foot_skating, &w.continuity};
    for (int k = 0; k < 5; ++k) *fields[k] = k == i ? 1.5 : 0.0;
    sets.push_back({std::string(names[i]) + " alone", w});
  }
  sets.push_back({"default", RenavWeights{}});
  RenavWeights all;
  all.foot_skating = 0.3;
  sets.push_back({"every term", all});
  return sets;
}

// The encoder's codes of the window's reference segment, then random ones.
std::vector<std::pair<Eigen::VectorXf, Eigen::VectorXf>> codes_for(const RenavWindow& w, std::mt19937& rng) {
  const runtime::NemfRuntime& rt = shipped_models().runtime;
  const runtime::LatentGaussians g = rt.encode_rotations(
      window_matrices(w.reference_segment, 0, w.reference_segment.num_frames(), rt.rig(), 0).local_rotations);
  return {{g.mu_l, g.mu_g},
          {normal_matrix(rt.config().zl, 1, rng).col(0), normal_matrix(rt.config().zg, 1, rng).col(0)}};
}

// Both energies at (z_l, z_g): every term and the total within 1e-5, the
// gradient within 1e-4 (relative).
Agreement compare(const RenavWindow& window, const RenavWeights& w, const Eigen::VectorXf& z_l,
                  const Eigen::VectorXf& z_g, const std::string& what) {
  const BothModels& m = shipped_models();
  RenavRuntimeEnergy energy(m.runtime, window, w);
  Eigen::VectorXf g_zl, g_zg;
  const RuntimeEnergyTerms r = energy.evaluate(z_l, z_g, &g_zl, &g_zg);
  const at::Tensor t_zl = to_tensor(z_l.transpose()).requires_grad_(true);
  const at::Tensor t_zg = to_tensor(z_g.transpose()).requires_grad_(true);
  const RenavEnergy t = evaluate_renav_energy(m.frozen, window, w, t_zl, t_zg);
  t.total.backward();
  Agreement a;
  const std::vector<double> d = term_differences(r, t, what);
  for (size_t i = 0; i < d.size(); ++i) {
    EXPECT_LT(d[i], kOutputTolerance) << what << ": " << t.terms[i].first << " " << r.terms[i].second;
    a.value = std::max(a.value, d[i]);
  }
  expect_total_and_gradient(r, t, g_zl, g_zg, t_zl, t_zg, what, &a);
  return a;
}

TEST(RenavRuntimeEnergy, EveryTermMatchesLibtorchOnWindowsOfTheWalk) {
  ScopedComputeThreads one_thread(1);
  std::mt19937 rng(11);
  for (const NamedWindow& nw : windows()) {
    ASSERT_EQ(nw.window.num_shared(), std::string(nw.name) == "later window" ? 15 : 0);
    const auto codes = codes_for(nw.window, rng);
    for (const NamedWeights& w : weight_sets()) {
      if (w.weights.path + w.weights.joints + w.weights.heading + w.weights.foot_skating == 0 &&
          nw.window.num_shared() == 0)
        continue;  // continuity alone is no term without shared frames
      Agreement worst;
      for (size_t c = 0; c < codes.size(); ++c) {
        const std::string what = std::string(nw.name) + ", " + w.name + (c == 0 ? ", encoded" : ", random");
        worst.merge(compare(nw.window, w.weights, codes[c].first, codes[c].second, what));
      }
      std::printf("%s, %s: values within %.2e, gradients within %.2e (relative)\n", nw.name, w.name.c_str(),
                  worst.value, worst.gradient);
    }
  }
}

// The gradient against central differences of the libtorch energy on the
// float64 prior, along the gradient and two random directions, with the
// default weights (foot_skating off: its contact probabilities are constants
// of its gradient, not of the energy, which the differences would see). The
// steps are 1e-6 and 1e-7: the path term's smoothed absolute value bends on a
// scale of 1e-3 m.
constexpr double kRenavDifferenceStep = 1e-6;
TEST(RenavRuntimeEnergy, GradientMatchesCentralDifferences) {
  ScopedComputeThreads one_thread(1);
  const BothModels& m = shipped_models();
  const NemfConfig& c = m.runtime.config();
  std::mt19937 rng(12);
  for (const NamedWindow& nw : windows()) {
    const RenavWeights w;  // no foot_skating: its contact probabilities are constants of the gradient, not of f
    const auto codes = codes_for(nw.window, rng);
    const Eigen::VectorXf& z_l = codes[1].first;
    const Eigen::VectorXf& z_g = codes[1].second;
    RenavRuntimeEnergy energy(m.runtime, nw.window, w);
    Eigen::VectorXf g_zl, g_zg;
    energy.evaluate(z_l, z_g, &g_zl, &g_zg);
    Eigen::VectorXd grad(c.zl + c.zg), z(c.zl + c.zg);
    grad << g_zl.cast<double>(), g_zg.cast<double>();
    z << z_l.cast<double>(), z_g.cast<double>();
    auto value_at = [&](const Eigen::VectorXd& step) {
      at::NoGradGuard no_grad;
      const Eigen::VectorXd x = z + step;
      const at::Tensor t = at::from_blob(const_cast<double*>(x.data()), {1, x.size()}, at::kDouble).clone();
      return evaluate_renav_energy(float64_model(), nw.window, w, t.narrow(1, 0, c.zl), t.narrow(1, c.zl, c.zg))
          .total.item<double>();
    };
    expect_directional_derivatives(grad, value_at, rng, nw.name, kRenavDifferenceStep);
  }
}

// The value alone (no gradient buffers) is the value of the full evaluation;
// the decoded window is the one the energy reads.
TEST(RenavRuntimeEnergy, ValueWithoutGradientAndDecodedWindow) {
  const BothModels& m = shipped_models();
  std::mt19937 rng(13);
  const RenavWindow& window = windows()[1].window;
  const auto codes = codes_for(window, rng);
  RenavRuntimeEnergy energy(m.runtime, window, RenavWeights{});
  Eigen::VectorXf g_zl, g_zg;
  const double with_gradient = energy.evaluate(codes[1].first, codes[1].second, &g_zl, &g_zg).total;
  EXPECT_EQ(energy.evaluate(codes[1].first, codes[1].second, nullptr, nullptr).total, with_gradient);
  MatrixRXf rotations, root, contacts;
  energy.decode_window(codes[1].first, codes[1].second, &rotations, &root, &contacts);
  const DecodedWindow d = decode_renav_window(m.frozen, window, to_tensor(codes[1].first.transpose()),
                                              to_tensor(codes[1].second.transpose()));
  EXPECT_LT(relative_difference(rotations, d.local_rotations), kOutputTolerance);
  EXPECT_LT(relative_difference(root, d.root_positions), kOutputTolerance);
  EXPECT_LT(relative_difference(contacts, d.contacts), kOutputTolerance);
}

// A window that does not fit the model is refused.
TEST(RenavRuntimeEnergy, RefusesAWindowThatDoesNotFit) {
  const runtime::NemfRuntime& rt = shipped_models().runtime;
  using Energy = RenavRuntimeEnergy;
  RenavWindow bad = windows()[0].window;
  bad.target_xz.conservativeResize(bad.length - 1, 2);
  EXPECT_THROW(Energy e(rt, bad, RenavWeights{}), InputError);
  bad = windows()[0].window;
  bad.reference_joints.conservativeResize(Eigen::NoChange, 6);
  EXPECT_THROW(Energy e(rt, bad, RenavWeights{}), InputError);
}


}  // namespace
}  // namespace mf::test
