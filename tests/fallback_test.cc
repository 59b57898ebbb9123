// The latent solvers' fallback to interpolation (tasks/latent/fallback.h): the
// rule needs both thresholds, the weights ramp over shared frames like the
// window cross-fade, a fallen window is interpolation's, and the jobs return
// the input rig's own interpolation with a note saying why.
#include <ATen/Parallel.h>
#include <gtest/gtest.h>

#include "prior/model/nemf.h"
#include "tasks/constraints/interpolation_fill.h"
#include "tasks/latent/fallback.h"
#include "tasks/latent/latent_solver.h"
#include "tasks/methods/jobs.h"
#include "tests/runtime_test_util.h"
#include "tests/test_util.h"

namespace mf {
namespace {

using test::max_abs_difference;

SolveSummary summary_with(double rotation, double position, double latent_prior) {
  SolveSummary s;
  s.final_terms = {{"rotation", rotation}, {"position", position}, {"latent_prior", latent_prior}};
  return s;
}

TEST(Fallback, DataTermsAreTheKeyTermsOnly) {
  EXPECT_DOUBLE_EQ(final_data_terms(summary_with(0.02, 0.03, 5.0)), 0.05);
}

TEST(Fallback, KeyMotionIsTheMeanJointTravelBetweenKnownFramesAcrossRuns) {
  Motion m = test::random_motion(test::tiny_rig().skeleton, 10, 30.0, 3);
  for (int f = 0; f < 10; ++f) m.root_positions[f] = Eigen::Vector3d(0.1 * f, 0, 0);
  for (int f = 0; f < 10; ++f)
    for (int j = 0; j < m.num_joints(); ++j) m.rotation(f, j) = m.rotation(0, j);
  // Runs 0..4 (0.4 m) and 4..9 (0.5 m); frames 9 and 10 would be adjacent.
  EXPECT_NEAR(key_motion_cm(m, {0, 4, 9}), 45.0, 1e-9);
  EXPECT_EQ(key_motion_cm(m, {0, 1, 2}), 0.0);
}

TEST(Fallback, TheRuleNeedsBothThresholds) {
  Motion still = test::random_motion(test::tiny_rig().skeleton, 10, 30.0, 3);
  for (int f = 0; f < 10; ++f) {
    still.root_positions[f] = Eigen::Vector3d(0.1 * f, 0, 0);  // 90 cm between the two keys
    for (int j = 0; j < still.num_joints(); ++j) still.rotation(f, j) = still.rotation(0, j);
  }
  InterpolationFallback rule;
  rule.enabled = true;
  rule.always_above = 0.3;
  rule.max_data_terms = 0.035;
  rule.max_data_terms_per_cm = 0.0013;
  // 0.05 > 0.035 but < 0.0013 * 90: kept (fast keys have larger data terms).
  EXPECT_FALSE(judge_window(rule, summary_with(0.02, 0.03, 0.0), still, {0, 9}).interpolated);
  // 0.2 > both.
  const WindowTrust t = judge_window(rule, summary_with(0.1, 0.1, 0.0), still, {0, 9});
  EXPECT_TRUE(t.interpolated);
  EXPECT_NEAR(t.data_terms, 0.2, 1e-12);
  EXPECT_NEAR(t.key_motion_cm, 90.0, 1e-9);
  // Above always_above, however far the keys move.
  rule.max_data_terms_per_cm = 1.0;
  EXPECT_FALSE(judge_window(rule, summary_with(0.1, 0.1, 0.0), still, {0, 9}).interpolated);
  EXPECT_TRUE(judge_window(rule, summary_with(0.2, 0.2, 0.0), still, {0, 9}).interpolated);
  rule.max_data_terms_per_cm = 0.0013;
  // 0.03 <= 0.035: kept however little the keys move.
  EXPECT_FALSE(judge_window(rule, summary_with(0.01, 0.02, 0.0), still, {0, 1}).interpolated);
  rule.enabled = false;
  EXPECT_FALSE(judge_window(rule, summary_with(0.1, 0.1, 0.0), still, {0, 9}).interpolated);
}

TEST(Fallback, WeightsRampOverTheFramesWindowsShare) {
  WindowSpan first{0, 10, 0, 0}, second{6, 10, 0, 4};
  const std::vector<double> w = interpolation_weights({first, second}, {WindowTrust{}, WindowTrust{1, 1, true}}, 16);
  const std::vector<double> expected = {0, 0, 0, 0, 0, 0, 0.2, 0.4, 0.6, 0.8, 1, 1, 1, 1, 1, 1};
  ASSERT_EQ(w.size(), expected.size());
  for (size_t f = 0; f < w.size(); ++f) EXPECT_NEAR(w[f], expected[f], 1e-12) << f;
  const std::vector<double> back = interpolation_weights({first, second}, {WindowTrust{1, 1, true}, WindowTrust{}}, 16);
  for (size_t f = 0; f < w.size(); ++f) EXPECT_NEAR(back[f], 1.0 - expected[f], 1e-12) << f;
}

NemfModel tiny_model() {
  NemfConfig c = test::tiny_nemf_config();
  c.pe_frequencies = 4;
  return test::tiny_prior(11, c, test::tiny_rig());
}

LatentSolverOptions quick() {
  LatentSolverOptions o = default_solver_options(LatentOptimizer::Lbfgs);
  o.max_iterations = 20;
  return o;
}

TEST(Fallback, AWindowOutOfThePriorsReachIsInterpolation) {
  at::set_num_threads(1);
  const runtime::NemfRuntime model = test::runtime_of(tiny_model());
  const Motion m = test::random_motion(model.rig().skeleton, 26, 30.0, 7);
  const MotionConstraints keys = MotionConstraints::full_pose({0, 6, 13, 25});
  const Motion interpolated = fill_by_interpolation(m, keys);

  LatentSolverOptions o = quick();
  o.fallback.enabled = true;
  o.fallback.always_above = 0.0;  // every fit is "out of reach"
  CompletionReport report;
  const Motion out = complete_motion(model, m, keys, o, {}, &report);
  ASSERT_EQ(report.trust.size(), 1u);
  EXPECT_TRUE(report.trust[0].interpolated);
  EXPECT_LT(max_abs_difference(out, interpolated), 1e-9);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("interpolation was used"), std::string::npos) << report.warnings[0];

  // Thresholds out of reach: the solver's own result, as without the rule.
  o.fallback.always_above = o.fallback.max_data_terms = 1e9;
  const Motion kept = complete_motion(model, m, keys, o, {}, &report);
  EXPECT_FALSE(report.trust[0].interpolated);
  EXPECT_TRUE(report.warnings.empty());
  EXPECT_EQ(max_abs_difference(kept, complete_motion(model, m, keys, quick())), 0.0);
  EXPECT_GT(max_abs_difference(kept, interpolated), 1e-3);

  // Alternatives (start noise) keep their own results.
  o.fallback.always_above = 0.0;
  o.start_noise = 0.5;
  complete_motion(model, m, keys, o, {}, &report);
  EXPECT_FALSE(report.trust[0].interpolated);
}

TEST(Fallback, JobsReturnTheInputsOwnInterpolationAndSayWhy) {
  at::set_num_threads(1);
  TaskContext ctx;
  ctx.model = test::shared_runtime_of(tiny_model());
  const Motion m = test::random_motion(ctx.model->rig().skeleton, 26, 30.0, 9);
  // A tiny random prior cannot fit random keys within the shipped thresholds.
  std::vector<std::string> warnings;
  const Motion out = run_fill(m, 5, 20, "nemf", ctx, &warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("the prior could not reach the keys"), std::string::npos) << warnings[0];
  EXPECT_EQ(max_abs_difference(out, interpolate_motion(m, known_frames_outside_gap(26, 5, 20))), 0.0);

  ctx.interpolation_fallback = false;
  warnings.clear();
  const Motion own = run_fill(m, 5, 20, "nemf", ctx, &warnings);
  EXPECT_TRUE(warnings.empty());
  EXPECT_GT(max_abs_difference(own, out), 1e-3);
}

}  // namespace
}  // namespace mf
