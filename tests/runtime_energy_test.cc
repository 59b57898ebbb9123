// The next layer of the Eigen runtime against libtorch: the 6D conversion and
// forward kinematics (prior/runtime/rotations.h, kinematics.h) and the latent
// energy with its gradient (tasks/latent/runtime_energy.h) against
// rotations_torch.h, kinematics_torch.h and evaluate_energy() with autograd
// (tasks/reference/energies.h), with the shipped model on windows of the sample
// walk, at its encoded codes and at random ones. Every term is compared on its
// own (weights with only that term on) and in mixes (the default; every term,
// with the keys' residuals blended into the output motion and without), under
// both penalties: values within 1e-5 and gradients within 1e-4, relative to
// the largest libtorch value (issue 56's bounds). Gradients are also checked
// against central differences (of the float64 prior for the energy), and the
// 6D conversion and FK against the double-precision single-pose code of
// rotations.h and motion.h.
#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "prior/model/representation.h"
#include "prior/motion/errors.h"
#include "prior/motion/kinematics_torch.h"
#include "prior/motion/rotations.h"
#include "prior/motion/rotations_torch.h"
#include "prior/runtime/kinematics.h"
#include "prior/runtime/rotations.h"
#include "prior/util/threads.h"
#include "tasks/latent/runtime_energy.h"
#include "tasks/latent/runtime_latent_energy.h"
#include "tasks/reference/energies.h"
#include "tests/runtime_test_util.h"

// In mf::test, where the helpers of runtime_test_util.h are.
namespace mf::test {
namespace {

Eigen::VectorXd flat(const MatrixRXf& m) {
  return Eigen::Map<const Eigen::VectorXf>(m.data(), m.size()).cast<double>();
}

TEST(RuntimeRotations, SixdToMatrixMatchesLibtorchAndTheDoubleConversion) {
  std::mt19937 rng(1);
  const int S = 50, J = 4;
  const MatrixRXf d6 = normal_matrix(S, J * 6, rng), g = normal_matrix(S, J * 9, rng);
  MatrixRXf rotations, g_d6;
  runtime::sixd_to_matrix(d6, &rotations);
  runtime::sixd_to_matrix_vjp(d6, g, &g_d6);
  const at::Tensor x = to_tensor(d6).view({S, J, 6}).requires_grad_(true);
  const at::Tensor m = torch_rot::sixd_to_matrix(x);
  (m.reshape({S, J * 9}) * to_tensor(g)).sum().backward();
  const double value = relative_difference(rotations, to_matrix(m.reshape({S, J * 9})));
  const double gradient = relative_difference(g_d6, to_matrix(x.grad().reshape({S, J * 6})));
  // rotations.h's Gram-Schmidt in double, an implementation of its own.
  MatrixRXf reference(S, J * 9);
  for (int s = 0; s < S; ++s) {
    for (int j = 0; j < J; ++j) {
      const Eigen::Matrix3d r = matrix_from_sixd(d6.row(s).segment<6>(j * 6).transpose().cast<double>());
      for (int a = 0; a < 9; ++a) reference(s, j * 9 + a) = static_cast<float>(r(a / 3, a % 3));
    }
  }
  const double to_double = relative_difference(rotations, reference);
  EXPECT_LT(value, kOutputTolerance);
  EXPECT_LT(gradient, kGradientTolerance);
  EXPECT_LT(to_double, kOutputTolerance);
  std::printf("6D -> matrix: value %.2e (double conversion %.2e), gradient %.2e\n", value, to_double, gradient);
  // <g, M(x)> through the double conversion.
  const Eigen::VectorXd x0 = flat(d6), gd = flat(g);
  auto value_at = [&](const Eigen::VectorXd& step) {
    double sum = 0;
    for (int n = 0; n < S * J; ++n) {
      const Eigen::Matrix3d r = matrix_from_sixd((x0 + step).segment<6>(n * 6));
      for (int a = 0; a < 9; ++a) sum += gd[n * 9 + a] * r(a / 3, a % 3);
    }
    return sum;
  };
  expect_directional_derivatives(flat(g_d6), value_at, rng, "6D -> matrix");
}

// Random unit quaternions for T frames of `skeleton` and a random root path,
// as a Motion and as the runtime's [T, J * 9] and [T, 3].
struct RandomPose {
  Motion motion;
  MatrixRXf local, root;
};

RandomPose random_pose(const Skeleton& skeleton, int T, std::mt19937& rng) {
  const int J = skeleton.num_joints();
  RandomPose p;
  p.motion = Motion::identity(skeleton, T, 30.0);
  p.local.resize(T, J * 9);
  p.root = normal_matrix(T, 3, rng);
  std::normal_distribution<double> n;
  for (int t = 0; t < T; ++t) {
    p.motion.root_positions[t] = p.root.row(t).transpose().cast<double>();
    for (int j = 0; j < J; ++j) {
      const Eigen::Quaterniond q = Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized();
      p.motion.rotation(t, j) = q;
      const Eigen::Matrix3d r = q.toRotationMatrix();
      for (int a = 0; a < 9; ++a) p.local(t, j * 9 + a) = static_cast<float>(r(a / 3, a % 3));
    }
  }
  return p;
}

TEST(RuntimeKinematics, ForwardKinematicsMatchesLibtorchAndTheDoubleFk) {
  const Skeleton& skeleton = shipped_models().runtime.rig().skeleton;
  const int T = 20, J = skeleton.num_joints();
  std::mt19937 rng(2);
  const RandomPose pose = random_pose(skeleton, T, rng);
  const runtime::Kinematics fk(skeleton);
  MatrixRXf positions, globals, g_local, g_root;
  fk.forward(pose.local, pose.root, &positions, &globals);
  const MatrixRXf g_pos = normal_matrix(T, J * 3, rng), g_glob = normal_matrix(T, J * 9, rng);
  fk.vjp(pose.local, globals, g_pos, &g_glob, &g_local, &g_root);
  const at::Tensor local = to_tensor(pose.local).view({T, J, 3, 3}).requires_grad_(true);
  const at::Tensor root = to_tensor(pose.root).requires_grad_(true);
  const FkTensors t = forward_kinematics(skeleton.parents, offsets_tensor(skeleton), local, root);
  ((t.positions.reshape({T, J * 3}) * to_tensor(g_pos)).sum() +
   (t.rotations.reshape({T, J * 9}) * to_tensor(g_glob)).sum())
      .backward();
  const double pos = relative_difference(positions, to_matrix(t.positions.reshape({T, J * 3})));
  const double rot = relative_difference(globals, to_matrix(t.rotations.reshape({T, J * 9})));
  const double grad_local = relative_difference(g_local, to_matrix(local.grad().reshape({T, J * 9})));
  const double grad_root = relative_difference(g_root, to_matrix(root.grad()));
  // motion.h's FK on quaternions in double.
  const GlobalPose reference = forward_kinematics(pose.motion);
  MatrixRXf ref_positions(T, J * 3);
  for (int f = 0; f < T; ++f) {
    for (int j = 0; j < J; ++j)
      ref_positions.row(f).segment<3>(j * 3) = reference.position(f, j).transpose().cast<float>();
  }
  const double to_double = relative_difference(positions, ref_positions);
  for (double d : {pos, rot, to_double}) EXPECT_LT(d, kOutputTolerance);
  for (double d : {grad_local, grad_root}) EXPECT_LT(d, kGradientTolerance);
  std::printf("FK T=%d: positions %.2e (double FK %.2e), rotations %.2e, d local %.2e, d root %.2e\n", T, pos,
              to_double, rot, grad_local, grad_root);
  // <g_pos, P> + <g_glob, R> through libtorch's FK in double.
  Eigen::VectorXd grad(T * J * 9 + T * 3), x0(T * J * 9 + T * 3);
  grad << flat(g_local), flat(g_root);
  x0 << flat(pose.local), flat(pose.root);
  const at::Tensor offsets = offsets_tensor(skeleton).to(at::kDouble);
  const at::Tensor tg_pos = to_tensor(g_pos).to(at::kDouble), tg_glob = to_tensor(g_glob).to(at::kDouble);
  auto value_at = [&](const Eigen::VectorXd& step) {
    const Eigen::VectorXd x = x0 + step;
    const at::Tensor tx = at::from_blob(const_cast<double*>(x.data()), {x.size()}, at::kDouble).clone();
    const FkTensors o = forward_kinematics(skeleton.parents, offsets, tx.narrow(0, 0, T * J * 9).view({T, J, 3, 3}),
                                           tx.narrow(0, T * J * 9, T * 3).view({T, 3}));
    return ((o.positions.reshape({T, J * 3}) * tg_pos).sum() + (o.rotations.reshape({T, J * 9}) * tg_glob).sum())
        .item<double>();
  };
  expect_directional_derivatives(grad, value_at, rng, "FK");
}

// ---------------------------------------------------------------------------
// The energy

// Weights with only `term` on, at `value`.
EnergyWeights only(double EnergyWeights::*term, double value) {
  EnergyWeights w;
  for (double EnergyWeights::*t :
       {&EnergyWeights::rotation, &EnergyWeights::position, &EnergyWeights::root_orientation,
        &EnergyWeights::root_translation, &EnergyWeights::effector, &EnergyWeights::contact, &EnergyWeights::trajectory,
        &EnergyWeights::trajectory_facing, &EnergyWeights::latent_prior, &EnergyWeights::foot_skating,
        &EnergyWeights::smoothness})
    w.*t = 0.0;
  w.*term = value;
  return w;
}

struct NamedWeights {
  const char* name;
  EnergyWeights weights;
};

std::vector<NamedWeights> weight_sets(Penalty penalty) {
  EnergyWeights with_prior;
  with_prior.latent_prior = 0.01;
  std::vector<NamedWeights> sets = {{"rotation", only(&EnergyWeights::rotation, 5.0)},
                                    {"position", only(&EnergyWeights::position, 10.0)},
                                    {"root_orientation", only(&EnergyWeights::root_orientation, 1.0)},
                                    {"root_translation", only(&EnergyWeights::root_translation, 10.0)},
                                    {"latent_prior", only(&EnergyWeights::latent_prior, 0.5)},
                                    {"default", EnergyWeights{}},
                                    {"default + latent_prior", with_prior}};
  for (NamedWeights& s : sets) s.weights.penalty = penalty;
  return sets;
}

// A window of the sample walk on the model's rig under `c`, anchored at its first key.
struct NamedProblem {
  const char* name;
  WindowProblem problem;
};

NamedProblem walk_problem(const char* name, const MotionConstraints& c, int length) {
  return {name, make_window_problem(shipped_models().frozen.rig(), walk_on_model_rig(), 0, length, c,
                                    c.keys.front().frame)};
}

// A gap of 30 frames after 10 known ones (the benchmarks' gap task), keys
// every 15 frames, and partial keys: some joints without the root position, the
// root position alone, and joints without the root.
const std::vector<NamedProblem>& problems() {
  static const std::vector<NamedProblem> p = [] {
    MotionConstraints partial = MotionConstraints::full_pose({0});
    PoseKey some_joints{20, {0, 1, 2, 3, 4, 9}, false, true};
    PoseKey root_only{34, {}, true, false};
    PoseKey no_root{47, {5, 6, 7, 12}, true, true};
    partial.keys.insert(partial.keys.end(), {some_joints, root_only, no_root});
    return std::vector<NamedProblem>{
        walk_problem("gap 30", MotionConstraints::full_pose({0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 40}), 41),
        walk_problem("keys every 15", MotionConstraints::full_pose({0, 15, 30, 45, 60}), 61),
        walk_problem("partial keys", partial, 52)};
  }();
  return p;
}

// A window of 41 frames of the walk with every constraint of the output
// terms: a key at 0 (the anchor) on the root and the first joints only (the
// others, never keyed, take no residual), a key of some joints without the
// root position and a key of the root position alone; end-effector targets
// off the walk, two contact pins and trajectory rows between the keys.
const WindowProblem& output_problem() {
  static const WindowProblem p = [] {
    const RigInfo& rig = shipped_models().frozen.rig();
    const Motion& walk = walk_on_model_rig();
    MotionConstraints c;
    c.keys = {PoseKey{0, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9}, true, true}, PoseKey{25, {0, 3, 4, 5}, false, true},
              PoseKey{40, {}, true, false}};
    c.effectors = {{12, rig.foot_joints[0], walk.root_positions[12] + Eigen::Vector3d(0.1, -0.8, 0.1), 1.0},
                   {33, rig.foot_joints[1], walk.root_positions[33] + Eigen::Vector3d(-0.1, -0.7, 0.2), 0.5}};
    c.contacts = {{rig.foot_joints[0], 14, 20}, {rig.foot_joints[1], 30, 36}};
    for (int f : {5, 15, 20, 35}) {
      const Eigen::Vector3d& r = walk.root_positions[f];
      c.trajectory.push_back({f, r.x() + 0.2, r.z() - 0.1, 0.3, 1.0});
    }
    return make_window_problem(rig, walk, 0, 41, c, 0);
  }();
  return p;
}

// Weights with each output term alone, all of them with the key terms, and
// all of them on the raw decoded motion (EnergyWeights::on_output off).
std::vector<NamedWeights> output_weight_sets(Penalty penalty) {
  EnergyWeights all;
  all.foot_skating = 1.0;
  all.smoothness = 1e-3;
  all.latent_prior = 0.01;
  EnergyWeights raw = all;
  raw.on_output = false;
  std::vector<NamedWeights> sets = {{"effector", only(&EnergyWeights::effector, 100.0)},
                                    {"contact", only(&EnergyWeights::contact, 10.0)},
                                    {"trajectory", only(&EnergyWeights::trajectory, 100.0)},
                                    {"trajectory_facing", only(&EnergyWeights::trajectory_facing, 30.0)},
                                    {"foot_skating", only(&EnergyWeights::foot_skating, 1.0)},
                                    {"smoothness", only(&EnergyWeights::smoothness, 1e-3)},
                                    {"every term", all},
                                    {"every term, raw output", raw}};
  for (NamedWeights& s : sets) s.weights.penalty = penalty;
  return sets;
}

// The codes the encoder gives the problem's window of the walk, and random ones.
std::vector<std::pair<Eigen::VectorXf, Eigen::VectorXf>> codes_for(const WindowProblem& p, std::mt19937& rng) {
  const NemfModel& model = shipped_models().frozen;
  const WindowTensors w = window_tensors(walk_on_model_rig(), 0, p.length, model.rig(), p.anchor);
  const NemfLatent encoded = model.encode(w.local_rotations, at::ones({1, p.length}));
  const NemfConfig& c = model.config();
  return {{to_vector(encoded.mu_l), to_vector(encoded.mu_g)},
          {normal_matrix(c.zl, 1, rng).col(0), normal_matrix(c.zg, 1, rng).col(0)}};
}

// Both energies and their gradients at (z_l, z_g): every term and the total
// compared relative to the libtorch value (a term float does not give to
// 1e-5, libtorch's neither, relative to the float64 prior's value), the
// gradient relative to its largest entry.
Agreement compare_energies(const WindowProblem& problem, const EnergyWeights& w, const Eigen::VectorXf& z_l,
                           const Eigen::VectorXf& z_g, const std::string& what) {
  const BothModels& m = shipped_models();
  RuntimeEnergy energy(m.runtime);
  Eigen::VectorXf g_zl, g_zg;
  const RuntimeEnergyTerms r =
      energy.evaluate(to_runtime_problem(problem, m.runtime.rig().num_joints()), w, z_l, z_g, &g_zl, &g_zg);
  const at::Tensor t_zl = to_tensor(z_l.transpose()).requires_grad_(true);
  const at::Tensor t_zg = to_tensor(z_g.transpose()).requires_grad_(true);
  const EnergyTerms t = evaluate_energy(m.frozen, problem, w, t_zl, t_zg);
  t.total.backward();
  Agreement a;
  const std::vector<double> differences = term_differences(r, t, what);
  for (size_t i = 0; i < differences.size(); ++i) {
    const double ref = t.terms[i].second.item<double>();
    const double d = differences[i];
    a.value = std::max(a.value, d);
    if (d < kOutputTolerance) continue;
    // A velocity of a few mm per frame (contact) loses digits to the
    // difference of positions of metres in float, libtorch's as well: then
    // the runtime must be that close to the float64 prior's value.
    const double exact = evaluate_energy(float64_model(), problem, w, t_zl.detach().to(at::kDouble),
                                         t_zg.detach().to(at::kDouble))
                             .terms[i]
                             .second.item<double>();
    const double d64 = std::abs(r.terms[i].second - exact) / std::abs(exact);
    EXPECT_LT(d64, kOutputTolerance) << what << ": " << t.terms[i].first << " " << r.terms[i].second << " vs " << ref
                                     << " (float64 " << exact << ")";
    std::printf("%s: %s %.2e from libtorch's float value, %.2e from float64's (libtorch's float %.2e)\n", what.c_str(),
                t.terms[i].first.c_str(), d, d64, std::abs(ref - exact) / std::abs(exact));
  }
  expect_total_and_gradient(r, t, g_zl, g_zg, t_zl, t_zg, what, &a);
  return a;
}

TEST(RuntimeEnergy, EveryTermMatchesLibtorchOnWindowsOfTheWalk) {
  ScopedComputeThreads one_thread(1);
  ScopedGemmBackend blas(runtime::GemmBackend::Blas);
  std::mt19937 rng(3);
  for (const NamedProblem& p : problems()) {
    const auto codes = codes_for(p.problem, rng);
    for (Penalty penalty : {Penalty::Squared, Penalty::Absolute}) {
      for (const NamedWeights& w : weight_sets(penalty)) {
        Agreement worst;
        for (size_t c = 0; c < codes.size(); ++c) {
          const std::string what = std::string(p.name) + ", " + w.name + (c == 0 ? ", encoded" : ", random") +
                                   (penalty == Penalty::Squared ? ", squared" : ", absolute");
          const Agreement a = compare_energies(p.problem, w.weights, codes[c].first, codes[c].second, what);
          worst.value = std::max(worst.value, a.value);
          worst.gradient = std::max(worst.gradient, a.gradient);
        }
        std::printf("energy %-13s %-22s %-8s: values %.2e, gradient %.2e\n", p.name, w.name,
                    penalty == Penalty::Squared ? "squared" : "absolute", worst.value, worst.gradient);
      }
    }
  }
}

// The output terms (and the residual blending they see) on the window with
// every kind of constraint, alone and together, against libtorch.
TEST(RuntimeEnergy, OutputTermsMatchLibtorch) {
  ScopedComputeThreads one_thread(1);
  ScopedGemmBackend blas(runtime::GemmBackend::Blas);
  std::mt19937 rng(6);
  const WindowProblem& problem = output_problem();
  const auto codes = codes_for(problem, rng);
  for (Penalty penalty : {Penalty::Squared, Penalty::Absolute}) {
    for (const NamedWeights& w : output_weight_sets(penalty)) {
      Agreement worst;
      for (size_t c = 0; c < codes.size(); ++c) {
        const std::string what = std::string("output terms, ") + w.name + (c == 0 ? ", encoded" : ", random") +
                                 (penalty == Penalty::Squared ? ", squared" : ", absolute");
        const Agreement a = compare_energies(problem, w.weights, codes[c].first, codes[c].second, what);
        worst.value = std::max(worst.value, a.value);
        worst.gradient = std::max(worst.gradient, a.gradient);
      }
      std::printf("energy %-22s %-8s: values %.2e, gradient %.2e\n", w.name,
                  penalty == Penalty::Squared ? "squared" : "absolute", worst.value, worst.gradient);
    }
  }
}

// The runtime's kernels against the BLAS (both runtime), at random codes on
// the walk's windows and the window with every kind of constraint: values
// within 1e-5, gradients within 1e-4 relative (ScopedGemmBackend says why not
// at the encoded codes).
TEST(RuntimeEnergy, KernelsMatchTheBlasAtRandomCodes) {
  if (runtime::cpu_kernel_isa() == runtime::KernelIsa::None) GTEST_SKIP() << "no kernels on this CPU";
  ScopedComputeThreads one_thread(1);
  const BothModels& m = shipped_models();
  std::mt19937 rng(8);
  const NemfConfig& c = m.runtime.config();
  const NamedProblem output{"output terms", output_problem()};
  for (const NamedProblem* p : {&problems()[0], &problems()[1], &problems()[2], &output}) {
    const RuntimeWindowProblem rp = to_runtime_problem(p->problem, m.runtime.rig().num_joints());
    const EnergyWeights w = p == &output ? output_weight_sets(Penalty::Squared)[6].weights : EnergyWeights{};
    for (int draw = 0; draw < 2; ++draw) {
      const Eigen::VectorXf z_l = normal_matrix(c.zl, 1, rng).col(0), z_g = normal_matrix(c.zg, 1, rng).col(0);
      Eigen::VectorXf g[2][2];
      double value[2];
      for (int b = 0; b < 2; ++b) {
        ScopedGemmBackend backend(b == 0 ? runtime::GemmBackend::Kernels : runtime::GemmBackend::Blas);
        RuntimeEnergy energy(m.runtime);
        value[b] = energy.evaluate(rp, w, z_l, z_g, &g[b][0], &g[b][1]).total;
      }
      Eigen::VectorXf kernels(c.zl + c.zg), blas(c.zl + c.zg);
      kernels << g[0][0], g[0][1];
      blas << g[1][0], g[1][1];
      EXPECT_LT(std::abs(value[0] - value[1]) / std::abs(value[1]), kOutputTolerance) << p->name << " " << draw;
      EXPECT_LT(relative_vector_difference(kernels, blas), kGradientTolerance) << p->name << " " << draw;
    }
  }
}

// The runtime energy's gradient against central differences of the float64
// prior's libtorch energy, term by term, at random codes.
TEST(RuntimeEnergy, GradientMatchesFiniteDifferences) {
  ScopedComputeThreads one_thread(1);
  const BothModels& m = shipped_models();
  std::mt19937 rng(4);
  const NemfConfig& c = m.runtime.config();
  const NamedProblem output{"output terms", output_problem()};
  for (const NamedProblem* p : {&problems()[0], &problems()[2], &output}) {
    const RuntimeWindowProblem rp = to_runtime_problem(p->problem, m.runtime.rig().num_joints());
    const Eigen::VectorXf z_l = normal_matrix(c.zl, 1, rng).col(0), z_g = normal_matrix(c.zg, 1, rng).col(0);
    std::vector<NamedWeights> sets;
    if (p == &output) {
      // Without foot_skating: its contact probabilities are constants of its
      // gradient (detached, as in energies.cc), not of its value, so
      // differences do not give that gradient; libtorch's autograd
      // (OutputTermsMatchLibtorch) does.
      for (NamedWeights w : output_weight_sets(Penalty::Squared)) {
        if (w.weights.foot_skating > 0 && w.weights.effector == 0) continue;  // foot_skating alone
        w.weights.foot_skating = 0;
        sets.push_back(w);
      }
      EnergyWeights absolute = output_weight_sets(Penalty::Absolute)[6].weights;
      absolute.foot_skating = 0;
      sets.push_back({"every term, absolute", absolute});
    } else {
      sets = weight_sets(Penalty::Squared);
      sets.push_back({"default, absolute", weight_sets(Penalty::Absolute)[5].weights});
    }
    for (const NamedWeights& w : sets) {
      RuntimeEnergy energy(m.runtime);
      Eigen::VectorXf g_zl, g_zg;
      energy.evaluate(rp, w.weights, z_l, z_g, &g_zl, &g_zg);
      Eigen::VectorXd grad(c.zl + c.zg), z(c.zl + c.zg);
      grad << g_zl.cast<double>(), g_zg.cast<double>();
      z << z_l.cast<double>(), z_g.cast<double>();
      auto value_at = [&](const Eigen::VectorXd& step) {
        at::NoGradGuard no_grad;
        const Eigen::VectorXd x = z + step;
        const at::Tensor t = at::from_blob(const_cast<double*>(x.data()), {1, x.size()}, at::kDouble).clone();
        return evaluate_energy(float64_model(), p->problem, w.weights, t.narrow(1, 0, c.zl),
                               t.narrow(1, c.zl, c.zg))
            .total.item<double>();
      };
      const std::string what = std::string("energy ") + p->name + ", " + w.name;
      expect_directional_derivatives(grad, value_at, rng, what.c_str());
    }
  }
}

// The value alone (no gradient buffers) is the value of the full evaluation.
TEST(RuntimeEnergy, ValueWithoutGradientIsTheSame) {
  const BothModels& m = shipped_models();
  const int J = m.runtime.rig().num_joints();
  std::mt19937 rng(5);
  const Eigen::VectorXf z_l = normal_matrix(m.runtime.config().zl, 1, rng).col(0);
  const Eigen::VectorXf z_g = normal_matrix(m.runtime.config().zg, 1, rng).col(0);
  const std::pair<RuntimeWindowProblem, EnergyWeights> cases[] = {
      {to_runtime_problem(problems()[1].problem, J), EnergyWeights{}},
      {to_runtime_problem(output_problem(), J), output_weight_sets(Penalty::Squared)[6].weights}};
  RuntimeEnergy energy(m.runtime);
  for (const auto& [rp, w] : cases) {
    Eigen::VectorXf g_zl, g_zg;
    const double with_gradient = energy.evaluate(rp, w, z_l, z_g, &g_zl, &g_zg).total;
    const double alone = energy.evaluate(rp, w, z_l, z_g, nullptr, nullptr).total;
    EXPECT_GT(alone, 0.0);
    EXPECT_EQ(alone, with_gradient);
  }
}

// Constraints that do not fit the window are refused, whatever the weights.
TEST(RuntimeEnergy, RefusesConstraintsOutsideTheWindow) {
  const BothModels& m = shipped_models();
  const int J = m.runtime.rig().num_joints();
  const RuntimeWindowProblem good = to_runtime_problem(output_problem(), J);
  const Eigen::VectorXf z_l = Eigen::VectorXf::Zero(m.runtime.config().zl);
  const Eigen::VectorXf z_g = Eigen::VectorXf::Zero(m.runtime.config().zg);
  RuntimeEnergy energy(m.runtime);
  EXPECT_GT(energy.evaluate(good, EnergyWeights{}, z_l, z_g, nullptr, nullptr).total, 0.0);
  RuntimeWindowProblem effector = good, pin = good, trajectory = good, sizes = good;
  effector.effector_joints[0] = J;
  pin.pin_to[0] = good.length * J;
  trajectory.trajectory_frames[0] = good.length;
  sizes.effector_weights.resize(1);
  for (const RuntimeWindowProblem* p : {&effector, &pin, &trajectory, &sizes})
    EXPECT_THROW(energy.evaluate(*p, EnergyWeights{}, z_l, z_g, nullptr, nullptr), InputError);
}

}  // namespace
}  // namespace mf::test
