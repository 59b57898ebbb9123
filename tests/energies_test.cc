// Energies of the latent solvers (tasks/reference/energies.h): zero at a perfect fit and
// positive otherwise, gradients to the latents only, partial keys that never
// read what they do not constrain, constraint validation, and the
// interpolation initialiser.
#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "prior/model/nemf.h"
#include "prior/model/representation.h"
#include "prior/motion/errors.h"
#include "prior/motion/kinematics_torch.h"
#include "tasks/constraints/interpolation_fill.h"
#include "tasks/reference/energies.h"
#include "tasks/latent/initializers.h"
#include "tests/runtime_test_util.h"
#include "tests/test_util.h"

namespace mf {
namespace {

EnergyWeights all_terms() {
  EnergyWeights w;
  w.latent_prior = 0.0;
  w.foot_skating = 0.0;
  w.smoothness = 0.0;
  return w;
}

// A problem whose targets are exactly what (z_l, z_g) decode to: full keys at
// `keys`, effectors on two joints, anchored at keys[0].
WindowProblem problem_from_decode(const NemfModel& model, const at::Tensor& zl, const at::Tensor& zg,
                                  const std::vector<int64_t>& keys, int T) {
  const RigInfo& rig = model.rig();
  const int J = rig.num_joints();
  const int K = static_cast<int>(keys.size());
  WindowProblem p;
  p.length = T;
  p.anchor = static_cast<int>(keys[0]);
  at::NoGradGuard no_grad;
  DecodedWindow d;
  {
    WindowProblem anchor_only;
    anchor_only.length = T;
    anchor_only.anchor = p.anchor;
    d = decode_window(model, anchor_only, zl, zg);
  }
  p.key_frames = at::tensor(keys, at::kLong);
  p.key_rotations = test::window_rotations(d).index_select(0, p.key_frames).clone();
  p.key_rotation_mask = at::ones({K, J});
  p.key_position_mask = at::ones({K, J});
  p.key_position_mask.select(1, 0).zero_();
  p.key_positions = forward_kinematics(rig.skeleton.parents, offsets_tensor(rig.skeleton), p.key_rotations,
                                       at::zeros({K, 3}))
                        .positions;
  p.key_root = test::window_root_positions(d).index_select(0, p.key_frames).clone();
  p.key_root_mask = at::ones({K});
  at::Tensor pos =
      forward_kinematics(rig.skeleton.parents, offsets_tensor(rig.skeleton), test::window_rotations(d).unsqueeze(0),
                         test::window_root_positions(d).unsqueeze(0))
          .positions;
  p.effector_frames = at::tensor(std::vector<int64_t>{3, 9}, at::kLong);
  p.effector_joints = at::tensor(std::vector<int64_t>{rig.foot_joints[0], 2}, at::kLong);
  p.effector_targets = at::stack({pos[0][3][rig.foot_joints[0]], pos[0][9][2]}).clone();
  p.effector_weights = at::ones({2});
  return p;
}

double term(const EnergyTerms& e, const std::string& name) {
  for (const auto& t : e.terms) {
    if (t.first == name) return t.second.item<double>();
  }
  ADD_FAILURE() << "no term " << name;
  return std::numeric_limits<double>::quiet_NaN();
}

TEST(Energies, ZeroAtAPerfectFitAndPositiveOtherwise) {
  at::set_num_threads(1);
  NemfModel model = test::tiny_prior(11);
  at::manual_seed(5);
  at::Tensor zl = at::randn({1, 8}), zg = at::randn({1, 4});
  WindowProblem p = problem_from_decode(model, zl, zg, {2, 10, 20}, 24);
  for (Penalty pen : {Penalty::Squared, Penalty::Absolute}) {
    EnergyWeights w = all_terms();
    w.penalty = pen;
    EnergyTerms e = evaluate_energy(model, p, w, zl, zg);
    ASSERT_EQ(e.terms.size(), 5u);
    for (const char* name : {"rotation", "position", "root_orientation", "root_translation", "effector"}) {
      EXPECT_NEAR(term(e, name), 0.0, 2e-3) << name;
    }
    EnergyTerms off = evaluate_energy(model, p, w, zl + 0.5 * at::randn({1, 8}), zg + 0.5 * at::randn({1, 4}));
    for (const char* name : {"rotation", "position", "root_orientation", "root_translation", "effector"}) {
      EXPECT_GT(term(off, name), 10 * std::max(term(e, name), 1e-6)) << name;
    }
    EXPECT_GT(off.total.item<double>(), e.total.item<double>());
  }
  // The regularisers: positive on any motion, the prior exactly 0.5 |z|^2.
  EnergyWeights r;
  r.rotation = r.position = r.root_orientation = r.root_translation = r.effector = 0.0;
  r.latent_prior = 1.0;
  r.foot_skating = 1.0;
  r.smoothness = 1.0;
  EnergyTerms e = evaluate_energy(model, p, r, zl, zg);
  EXPECT_NEAR(term(e, "latent_prior"), 0.5 * (zl.square().sum() + zg.square().sum()).item<double>(), 1e-4);
  EXPECT_GT(term(e, "foot_skating"), 0.0);
  EXPECT_GT(term(e, "smoothness"), 0.0);
  EXPECT_NEAR(e.total.item<double>(),
              term(e, "latent_prior") + term(e, "foot_skating") + term(e, "smoothness"), 1e-4);
}

TEST(Energies, GradientsFlowToTheLatentsOnly) {
  at::set_num_threads(1);
  NemfModel model = test::tiny_prior(11);
  at::manual_seed(6);
  at::Tensor zl0 = at::randn({1, 8}), zg0 = at::randn({1, 4});
  WindowProblem p = problem_from_decode(model, zl0, zg0, {0, 12, 23}, 24);
  at::Tensor zl = (zl0 + 0.3).requires_grad_(true), zg = (zg0 - 0.3).requires_grad_(true);
  EnergyWeights w = all_terms();
  w.latent_prior = 0.01;
  w.foot_skating = 0.1;
  w.smoothness = 1e-4;
  EnergyTerms e = evaluate_energy(model, p, w, zl, zg);
  e.total.backward();
  ASSERT_TRUE(zl.grad().defined());
  ASSERT_TRUE(zg.grad().defined());
  EXPECT_GT(zl.grad().abs().sum().item<double>(), 0.0);
  EXPECT_GT(zg.grad().abs().sum().item<double>(), 0.0);
  EXPECT_TRUE(at::isfinite(zl.grad()).all().item<bool>());
  for (const auto& param : model.named_parameters()) {
    EXPECT_FALSE(param.second.requires_grad()) << param.first;
    EXPECT_FALSE(param.second.grad().defined()) << param.first;
  }
}

TEST(Energies, KeysOnlyDecodeMatchesDenseDecode) {
  // Without dense terms only the key frames are decoded; the keyed terms must
  // not depend on which path computed them.
  at::set_num_threads(1);
  NemfModel model = test::tiny_prior(11);
  at::manual_seed(7);
  at::Tensor zl = at::randn({1, 8}), zg = at::randn({1, 4});
  WindowProblem p = problem_from_decode(model, zl, zg, {1, 7, 15}, 20);
  at::Tensor zl2 = zl + 0.4, zg2 = zg - 0.2;
  EnergyWeights keyed = all_terms();
  keyed.root_translation = 0.0;
  keyed.effector = 0.0;
  EnergyWeights dense = all_terms();  // root_translation makes it decode every frame
  EnergyTerms a = evaluate_energy(model, p, keyed, zl2, zg2);
  EnergyTerms b = evaluate_energy(model, p, dense, zl2, zg2);
  for (const char* name : {"rotation", "position", "root_orientation"}) {
    EXPECT_NEAR(term(a, name), term(b, name), 1e-5 * std::max(1.0, term(a, name))) << name;
  }
}

TEST(Energies, WindowProblemReadsOnlyConstrainedValues) {
  NemfModel model = test::tiny_prior(11);
  const RigInfo& rig = model.rig();
  Motion m = test::random_motion(rig.skeleton, 20, 30.0, 4);
  MotionConstraints c;
  PoseKey root_only;
  root_only.frame = 2;
  root_only.joints = {0};
  PoseKey legs;
  legs.frame = 9;
  legs.joints = {3, 4, 5, 6};
  legs.root_position = false;
  c.keys = {root_only, legs};
  c.validate(m.num_frames(), m.num_joints());
  Motion poisoned = m;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int f = 0; f < 20; ++f) {
    for (int j = 0; j < m.num_joints(); ++j) {
      const bool read = (f == 2 && j == 0) || (f == 9 && j >= 3);
      if (!read) poisoned.rotation(f, j) = Eigen::Quaterniond(nan, nan, nan, nan);
    }
    if (f != 2) poisoned.root_positions[f] = Eigen::Vector3d(nan, nan, nan);
  }
  WindowProblem a = make_window_problem(rig, m, 0, 20, c, 2);
  WindowProblem b = make_window_problem(rig, poisoned, 0, 20, c, 2);
  EXPECT_TRUE(at::equal(a.key_rotations, b.key_rotations));
  EXPECT_TRUE(at::equal(a.key_root, b.key_root));
  EXPECT_TRUE(at::isfinite(b.key_positions).all().item<bool>());
  // Masks: key 0 the root only (no position term), key 1 the legs (no position:
  // the root's rotation is not given at that key).
  EXPECT_EQ(a.key_rotation_mask.sum().item<float>(), 5.0f);
  EXPECT_EQ(a.key_position_mask.sum().item<float>(), 0.0f);
  EXPECT_EQ(a.key_root_mask[0].item<float>(), 1.0f);
  EXPECT_EQ(a.key_root_mask[1].item<float>(), 0.0f);
  // Canonical: the anchor's root on the origin.
  EXPECT_NEAR(a.key_root[0][0].item<float>(), 0.0f, 1e-6);
  EXPECT_NEAR(a.key_root[0][2].item<float>(), 0.0f, 1e-6);

  // The interpolation fill reads nothing else either, and gives finite poses.
  Motion filled = fill_by_interpolation(poisoned, c);
  for (const auto& q : filled.rotations) EXPECT_TRUE(q.coeffs().allFinite());
  for (const auto& p : filled.root_positions) EXPECT_TRUE(p.allFinite());
  EXPECT_EQ(filled.rotation(5, 4).coeffs(), m.rotation(9, 4).normalized().coeffs());  // held before the only leg key
}

TEST(Energies, PartialKeysIgnoreUnconstrainedJoints) {
  at::set_num_threads(1);
  NemfModel model = test::tiny_prior(11);
  at::manual_seed(8);
  at::Tensor zl = at::randn({1, 8}), zg = at::randn({1, 4});
  WindowProblem p = problem_from_decode(model, zl, zg, {0, 8, 16}, 20);
  // Constrain only the legs (3..6) at every key: the rotation term must not
  // change when the other joints' targets change.
  p.key_rotation_mask.zero_();
  p.key_rotation_mask.narrow(1, 3, 4).fill_(1.0f);
  p.key_position_mask.zero_();
  EnergyWeights w;
  w.root_translation = w.effector = w.root_orientation = 0.0;
  const double before = evaluate_energy(model, p, w, zl + 0.2, zg).total.item<double>();
  const at::Tensor flip = at::diag(at::tensor({-1.0f, -1.0f, 1.0f}));  // 180 degrees about z
  p.key_rotations.narrow(1, 0, 3).copy_(flip.expand({3, 3, 3, 3}));
  const double after = evaluate_energy(model, p, w, zl + 0.2, zg).total.item<double>();
  EXPECT_DOUBLE_EQ(before, after);
  p.key_rotations.narrow(1, 4, 1).copy_(flip.expand({3, 1, 3, 3}));
  const double changed = evaluate_energy(model, p, w, zl + 0.2, zg).total.item<double>();
  EXPECT_GT(changed, before + 0.1);
}

TEST(Energies, ConstraintValidation) {
  MotionConstraints c = MotionConstraints::full_pose({0, 5, 9});
  EXPECT_NO_THROW(c.validate(10, 7));
  EXPECT_THROW(c.validate(9, 7), InputError);  // frame 9 out of range
  MotionConstraints unsorted = MotionConstraints::full_pose({5, 0});
  EXPECT_THROW(unsorted.validate(10, 7), InputError);
  MotionConstraints no_root;
  PoseKey legs;
  legs.frame = 1;
  legs.joints = {3, 4};
  no_root.keys = {legs};
  EXPECT_THROW(no_root.validate(10, 7), InputError);
  MotionConstraints bad_joint = MotionConstraints::full_pose({0});
  bad_joint.keys[0].joints = {0, 9};
  EXPECT_THROW(bad_joint.validate(10, 7), InputError);
  MotionConstraints bad_effector = MotionConstraints::full_pose({0});
  bad_effector.effectors.push_back({3, 2, Eigen::Vector3d(std::nan(""), 0, 0), 1.0});
  EXPECT_THROW(bad_effector.validate(10, 7), InputError);
  MotionConstraints s = MotionConstraints::full_pose({0, 5, 9}).slice(4, 6);
  ASSERT_EQ(s.keys.size(), 2u);
  EXPECT_EQ(s.keys[0].frame, 1);
  EXPECT_EQ(s.keys[1].frame, 5);
}

TEST(Initializers, InterpolationEncoderMatchesEncodingTheInterpolatedWindow) {
  at::set_num_threads(1);
  const runtime::NemfRuntime model = test::runtime_of(test::tiny_prior(11));
  Motion m = test::random_motion(model.rig().skeleton, 24, 30.0, 6);
  MotionConstraints c = MotionConstraints::full_pose({0, 11, 23});
  InitRequest r;
  r.model = &model;
  r.window = &m;
  r.constraints = &c;
  r.anchor = 0;
  InitialGuess g = make_initializer("interp-encoder")->initialize(r);
  ASSERT_EQ(g.z_l.size(), 8);
  ASSERT_EQ(g.z_g.size(), 4);
  EXPECT_TRUE(g.z_l.allFinite());
  EXPECT_GT(g.z_l.norm(), 0.0f);
  InitialGuess again = InterpolationEncoderInitializer().initialize(r);
  EXPECT_EQ(g.z_l, again.z_l);
  EXPECT_THROW(make_initializer("nope"), InputError);
  EXPECT_EQ(make_initializer("zero")->initialize(r).z_l.cwiseAbs().sum(), 0.0f);
}

}  // namespace
}  // namespace mf
