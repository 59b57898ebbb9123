// The latent solver on the Eigen runtime's energy (complete_motion(),
// tasks/latent/latent_solver.h): with the shipped model on windows of the
// sample walk, L-BFGS on the Eigen energy ends where L-BFGS on the libtorch
// reference energy (TaskContext::reference, tasks/reference/libtorch_energies.h)
// does (the energies agree to about 1e-6, so the paths differ only in the last
// digits), with keys alone and with every kind of output constraint.
#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>

#include "prior/motion/errors.h"
#include "prior/util/threads.h"
#include "tasks/latent/latent_solver.h"
#include "tasks/latent/runtime_latent_energy.h"
#include "tasks/reference/energies.h"
#include "tests/runtime_test_util.h"

// In mf::test, where the helpers of runtime_test_util.h are.
namespace mf::test {
namespace {

// The largest angle (rad) between the local rotations of two motions.
double max_angle(const Motion& a, const Motion& b) {
  double worst = 0;
  for (size_t i = 0; i < a.rotations.size(); ++i) worst = std::max(worst, a.rotations[i].angularDistance(b.rotations[i]));
  return worst;
}

struct Solved {
  Motion motion;
  CompletionReport report;
};

Solved solve(const Motion& input, const MotionConstraints& c, const LatentSolverOptions& o, const TaskContext& ctx) {
  Solved s;
  s.motion = complete_motion(*ctx.model, input, c, o, ctx, &s.report);
  return s;
}

// The gap of 30 frames with an end-effector target, a contact pin and
// trajectory rows inside it. L-BFGS's path on it is chaotic: the libtorch
// solve from codes moved by 1e-6 (LatentSolverOptions::start_noise) ends
// 0.24 rad away after 5 iterations, and the two energies' float differences
// (1e-6) part the paths after about 10 (1e-2 rad), so the paths are compared
// over the first 5 iterations.
MotionConstraints output_constraints(const Motion& walk) {
  const RigInfo& rig = shipped_models().runtime.rig();
  MotionConstraints c = MotionConstraints::full_pose({0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 40});
  c.effectors.push_back({25, rig.foot_joints[0], walk.root_positions[25] + Eigen::Vector3d(0.1, -0.8, 0.1), 1.0});
  c.contacts.push_back({rig.foot_joints[1], 14, 18});
  for (int f : {15, 30}) c.trajectory.push_back({f, walk.root_positions[f].x() + 0.1, walk.root_positions[f].z(), 0.0, 1.0});
  return c;
}

TEST(LatentSolverRuntime, EigenEnergyEndsWhereTheLibtorchEnergyDoes) {
  ScopedComputeThreads one_thread(1);
  ScopedGemmBackend blas(runtime::GemmBackend::Blas);  // why: ScopedGemmBackend
  const Motion& walk = walk_on_model_rig();
  const struct {
    const char* name;
    Motion input;
    MotionConstraints constraints;
    int iterations;  // 0: the default cap
  } cases[] = {{"gap 30", walk.slice(0, 41), MotionConstraints::full_pose({0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 40}), 0},
               {"keys every 15", walk, MotionConstraints::full_pose({0, 15, 30, 45, 60}), 0},
               {"gap 30, output constraints, 5 iterations", walk.slice(0, 41), output_constraints(walk), 5}};
  for (const auto& c : cases) {
    LatentSolverOptions o = default_solver_options(LatentOptimizer::Lbfgs);
    if (c.iterations > 0) o.max_iterations = c.iterations;
    const Solved eigen = solve(c.input, c.constraints, o, shipped_context());
    const Solved torch = solve(c.input, c.constraints, o, shipped_context(/*libtorch=*/true));
    ASSERT_EQ(eigen.report.windows.size(), 1u) << c.name;
    ASSERT_EQ(torch.report.windows.size(), 1u) << c.name;
    const SolveSummary& e = eigen.report.windows[0];
    const SolveSummary& t = torch.report.windows[0];
    EXPECT_TRUE(e.runtime_energy) << c.name;
    EXPECT_FALSE(t.runtime_energy) << c.name;
    // The same start: the initial energies agree as the energies do.
    EXPECT_NEAR(e.initial_energy, t.initial_energy, 1e-5 * t.initial_energy) << c.name;
    ASSERT_EQ(e.final_terms.size(), t.final_terms.size()) << c.name;
    for (size_t i = 0; i < e.final_terms.size(); ++i) EXPECT_EQ(e.final_terms[i].first, t.final_terms[i].first);
    const double energy_gap = std::abs(e.final_energy - t.final_energy) / t.final_energy;
    const double angle = max_angle(eigen.motion, torch.motion);
    std::printf("%s: iterations %d / %d, final energy %.6g / %.6g (relative %.2e), largest angle %.2e rad\n", c.name,
                e.iterations, t.iterations, e.final_energy, t.final_energy, energy_gap, angle);
    // The Eigen solve also starts from the Eigen encoders' codes (6e-7 off
    // libtorch's) and decodes on the runtime: 1.3e-2 rad measured on the keys
    // every 15, where the paths part after a few iterations.
    EXPECT_LT(energy_gap, 1e-2) << c.name;
    EXPECT_LT(angle, 2e-2) << c.name;
  }
}

// L-BFGS and Adam minimise the Eigen energy whatever terms are active; a
// context with the libtorch reference energies (TaskContext::reference)
// minimises those.
TEST(LatentSolverRuntime, UsesTheEigenEnergyWithTheModelsRuntime) {
  ScopedComputeThreads one_thread(1);
  const Motion input = walk_on_model_rig().slice(0, 41);
  const MotionConstraints gap = MotionConstraints::full_pose({0, 9, 40});
  MotionConstraints effector = gap;
  effector.effectors.push_back(
      {20, shipped_models().runtime.rig().foot_joints[0], input.root_positions[20] + Eigen::Vector3d(0.1, -0.8, 0.1),
       1.0});
  LatentSolverOptions lbfgs = default_solver_options(LatentOptimizer::Lbfgs);
  lbfgs.max_iterations = 3;
  lbfgs.keyed_iterations = 2;
  LatentSolverOptions adam = default_solver_options(LatentOptimizer::Adam);
  adam.max_iterations = 3;
  LatentSolverOptions skating = lbfgs;
  skating.weights.foot_skating = 1.0;
  const struct {
    const char* name;
    MotionConstraints constraints;
    LatentSolverOptions options;
    TaskContext ctx;
    bool runtime;
  } cases[] = {{"gap", gap, lbfgs, shipped_context(), true},
               {"effector target", effector, lbfgs, shipped_context(), true},
               {"foot skating weight", gap, skating, shipped_context(), true},
               {"Adam", gap, adam, shipped_context(), true},
               {"L-BFGS on the libtorch reference", gap, lbfgs, shipped_context(true), false},
               {"Adam on the libtorch reference", gap, adam, shipped_context(true), false}};
  for (const auto& c : cases) {
    CompletionReport report;
    complete_motion(shipped_models().runtime, input, c.constraints, c.options, c.ctx, &report);
    ASSERT_EQ(report.windows.size(), 1u) << c.name;
    EXPECT_EQ(report.windows[0].runtime_energy, c.runtime) << c.name;
    EXPECT_GT(report.windows[0].iterations, 0) << c.name;
  }
}

// The runtime's energy as the optimiser sees it is the tensor energy's, terms,
// total and gradient; both optimisers minimise it, and a start of the wrong
// size is refused.
TEST(LatentSolverRuntime, RuntimeLatentEnergyIsTheFlatEnergy) {
  const BothModels& m = shipped_models();
  const int zl = m.runtime.config().zl, zg = m.runtime.config().zg;
  const WindowProblem problem =
      make_window_problem(m.frozen.rig(), walk_on_model_rig(), 0, 41, MotionConstraints::full_pose({0, 9, 40}), 0);
  const RuntimeWindowProblem rp = to_runtime_problem(problem, m.runtime.rig().num_joints());
  const EnergyWeights w;
  RuntimeEnergy evaluator(m.runtime);
  RuntimeLatentEnergy direct(evaluator, rp, w, zl, zg);
  FlatLatentEnergy flat(
      [&](const at::Tensor& z_l, const at::Tensor& z_g) { return evaluate_energy(m.frozen, problem, w, z_l, z_g); }, zl,
      zg);
  std::mt19937 rng(8);
  const Eigen::VectorXd x = normal_matrix(1, zl + zg, rng).row(0).transpose().cast<double>();
  double direct_total = 0, flat_total = 0;
  const auto direct_terms = direct.terms(x.data(), &direct_total);
  const auto flat_terms = flat.terms(x.data(), &flat_total);
  ASSERT_EQ(direct_terms.size(), flat_terms.size());
  for (size_t i = 0; i < flat_terms.size(); ++i) {
    EXPECT_EQ(direct_terms[i].first, flat_terms[i].first);
    EXPECT_NEAR(direct_terms[i].second, flat_terms[i].second, kOutputTolerance * flat_terms[i].second);
  }
  EXPECT_NEAR(direct_total, flat_total, kOutputTolerance * flat_total);
  Eigen::VectorXd g_direct(zl + zg), g_flat(zl + zg);
  EXPECT_EQ(direct.evaluate(x.data(), g_direct.data()), direct_total);
  flat.evaluate(x.data(), g_flat.data());
  EXPECT_LT((g_direct - g_flat).cwiseAbs().maxCoeff(), kGradientTolerance * g_flat.cwiseAbs().maxCoeff());

  for (LatentOptimizer method : {LatentOptimizer::Lbfgs, LatentOptimizer::Adam}) {
    LatentOptimizerStats stats;
    LatentOptimizerSettings settings;
    settings.optimizer = method;
    settings.max_iterations = 5;
    const Eigen::VectorXd solved = minimize_latent(direct, x, settings, TaskContext{}, &stats);
    EXPECT_GT(stats.iterations, 0);
    EXPECT_LT(direct.evaluate(solved.data(), nullptr), direct_total);
    EXPECT_THROW(minimize_latent(direct, x.head(zl), settings, TaskContext{}, &stats), InputError);
  }
}

}  // namespace
}  // namespace mf::test
