// Tests of the batched torch forward kinematics: a hand-computed chain, the
// Eigen forward_kinematics(const Motion&) as reference, gradients against
// finite differences, and batched shapes.
#include "prior/motion/kinematics_torch.h"

#include <gtest/gtest.h>
#include <torch/types.h>

#include <cmath>
#include <random>
#include <vector>

#include "prior/motion/errors.h"
#include "prior/motion/motion.h"
#include "prior/motion/rotations_torch.h"
#include "tests/gradient_check.h"
#include "tests/test_util.h"

namespace mf {
namespace {

double max_abs_diff(const at::Tensor& a, const at::Tensor& b) {
  return (a.detach().to(torch::kDouble) - b.detach().to(torch::kDouble)).abs().max().item<double>();
}

at::Tensor matrix_tensor(const Eigen::Matrix3d& m, at::ScalarType dtype = at::kDouble) {
  at::Tensor t = torch::empty({3, 3}, torch::kDouble);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) t[r][c] = m(r, c);
  return t.to(dtype);
}

// Local rotations [T, J, 4] and root positions [T, 3] of a motion.
at::Tensor motion_quats(const Motion& m, at::ScalarType dtype) {
  at::Tensor q = torch::empty({m.num_frames(), m.num_joints(), 4}, torch::kDouble);
  auto a = q.accessor<double, 3>();
  for (int f = 0; f < m.num_frames(); ++f)
    for (int j = 0; j < m.num_joints(); ++j) {
      const Eigen::Quaterniond& r = m.rotation(f, j);
      a[f][j][0] = r.w();
      a[f][j][1] = r.x();
      a[f][j][2] = r.y();
      a[f][j][3] = r.z();
    }
  return q.to(dtype);
}

at::Tensor motion_roots(const Motion& m, at::ScalarType dtype) {
  at::Tensor p = torch::empty({m.num_frames(), 3}, torch::kDouble);
  auto a = p.accessor<double, 2>();
  for (int f = 0; f < m.num_frames(); ++f)
    for (int k = 0; k < 3; ++k) a[f][k] = m.root_positions[f][k];
  return p.to(dtype);
}

TEST(KinematicsTorch, HandComputedTwoJointChain) {
  // Root at (1, 2, 3) turned 90 degrees about Z; child 1 m along the root's X,
  // itself turned 90 degrees about X.
  const std::vector<int> parents = {-1, 0};
  at::Tensor offsets = torch::tensor({0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f}).view({2, 3});
  Eigen::Matrix3d rz, rx;
  rz << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  rx << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  at::Tensor local = torch::stack({matrix_tensor(rz, at::kFloat), matrix_tensor(rx, at::kFloat)});  // [2, 3, 3]
  at::Tensor root = torch::tensor({1.0f, 2.0f, 3.0f});
  FkTensors fk = forward_kinematics(parents, offsets, local, root);
  ASSERT_EQ(fk.positions.sizes(), (at::IntArrayRef{2, 3}));
  ASSERT_EQ(fk.rotations.sizes(), (at::IntArrayRef{2, 3, 3}));
  // Child: (1, 2, 3) + Rz (1, 0, 0) = (1, 3, 3).
  EXPECT_LT(max_abs_diff(fk.positions, torch::tensor({1.0, 2.0, 3.0, 1.0, 3.0, 3.0}).view({2, 3})), 1e-6);
  // Rz Rx written out: [[0, 0, 1], [1, 0, 0], [0, 1, 0]].
  Eigen::Matrix3d expected;
  expected << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  EXPECT_LT(max_abs_diff(fk.rotations[0], matrix_tensor(rz)), 1e-7);
  EXPECT_LT(max_abs_diff(fk.rotations[1], matrix_tensor(expected)), 1e-7);
  // The root's offset row is ignored.
  at::Tensor offsets2 = offsets.clone();
  offsets2[0][1] = 5.0f;
  EXPECT_LT(max_abs_diff(forward_kinematics(parents, offsets2, local, root).positions, fk.positions), 1e-7);
}

TEST(KinematicsTorch, HandComputedBranchingChain) {
  // Root with two children; the grandchild hangs off the second child and
  // inherits both rotations. All rotations 90 degrees about Y: x -> -z, z -> x.
  const std::vector<int> parents = {-1, 0, 0, 2};
  at::Tensor offsets = torch::tensor({0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 2.0}).view({4, 3});
  Eigen::Matrix3d ry;
  ry << 0, 0, 1, 0, 1, 0, -1, 0, 0;
  at::Tensor local = matrix_tensor(ry).expand({4, 3, 3});
  FkTensors fk = forward_kinematics(parents, offsets, local, torch::zeros({3}, torch::kDouble));
  // Joint 1: Ry (0, 1, 0) = (0, 1, 0). Joint 2: Ry (1, 0, 0) = (0, 0, -1).
  // Joint 3: joint 2 + Ry Ry (0, 0, 2) = (0, 0, -1) + (0, 0, -2) = (0, 0, -3).
  at::Tensor expected = torch::tensor({0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, -3.0}).view({4, 3});
  EXPECT_LT(max_abs_diff(fk.positions, expected), 1e-12);
  EXPECT_LT(max_abs_diff(fk.rotations[3], matrix_tensor(ry * ry * ry)), 1e-12);
  EXPECT_EQ(fk.positions.scalar_type(), torch::kDouble);
}

TEST(KinematicsTorch, MatchesEigenForwardKinematics) {
  const Skeleton skel = test::small_skeleton();
  const Motion motion = test::random_motion(skel, 40, 30.0, 123);
  const GlobalPose pose = forward_kinematics(motion);
  at::Tensor local = torch_rot::quat_to_matrix(motion_quats(motion, at::kFloat));  // [T, J, 3, 3]
  FkTensors fk = forward_kinematics(skel.parents, offsets_tensor(skel), local, motion_roots(motion, at::kFloat));
  const int T = motion.num_frames(), J = motion.num_joints();
  ASSERT_EQ(fk.positions.sizes(), (at::IntArrayRef{T, J, 3}));
  ASSERT_EQ(fk.rotations.sizes(), (at::IntArrayRef{T, J, 3, 3}));
  EXPECT_EQ(fk.positions.scalar_type(), torch::kFloat);
  at::Tensor pos = fk.positions.to(torch::kDouble);
  at::Tensor rot = fk.rotations.to(torch::kDouble);
  auto pa = pos.accessor<double, 3>();
  auto ra = rot.accessor<double, 4>();
  for (int f = 0; f < T; ++f)
    for (int j = 0; j < J; ++j) {
      const Eigen::Vector3d& p = pose.position(f, j);
      const Eigen::Matrix3d r = pose.rotation(f, j).toRotationMatrix();
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(pa[f][j][k], p[k], 1e-5) << "frame " << f << " joint " << j;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) EXPECT_NEAR(ra[f][j][a][b], r(a, b), 1e-5) << "frame " << f << " joint " << j;
    }
}

TEST(KinematicsTorch, BatchedShapesMatchPerWindow) {
  const Skeleton skel = test::small_skeleton();
  const int B = 3, T = 8, J = skel.num_joints();
  std::vector<at::Tensor> rots, roots;
  for (int b = 0; b < B; ++b) {
    const Motion m = test::random_motion(skel, T, 30.0, 500 + b);
    rots.push_back(torch_rot::quat_to_matrix(motion_quats(m, at::kFloat)));
    roots.push_back(motion_roots(m, at::kFloat));
  }
  at::Tensor local = torch::stack(rots);  // [B, T, J, 3, 3]
  at::Tensor root = torch::stack(roots);  // [B, T, 3]
  const at::Tensor offsets = offsets_tensor(skel);
  FkTensors fk = forward_kinematics(skel.parents, offsets, local, root);
  ASSERT_EQ(fk.positions.sizes(), (at::IntArrayRef{B, T, J, 3}));
  ASSERT_EQ(fk.rotations.sizes(), (at::IntArrayRef{B, T, J, 3, 3}));
  for (int b = 0; b < B; ++b) {
    FkTensors one = forward_kinematics(skel.parents, offsets, rots[b], roots[b]);
    EXPECT_LT(max_abs_diff(fk.positions[b], one.positions), 1e-6);
    EXPECT_LT(max_abs_diff(fk.rotations[b], one.rotations), 1e-6);
  }
  // A root path shared by every window broadcasts against the rotations.
  FkTensors shared = forward_kinematics(skel.parents, offsets, local, roots[0]);
  ASSERT_EQ(shared.positions.sizes(), (at::IntArrayRef{B, T, J, 3}));
  EXPECT_LT(max_abs_diff(shared.positions[0], fk.positions[0]), 1e-6);
  EXPECT_LT(max_abs_diff(shared.positions.select(-2, 0)[2], roots[0]), 1e-7);
}

TEST(KinematicsTorch, GradientsMatchFiniteDifferences) {
  // Loss = sum of FK positions weighted by fixed random numbers, as a function of
  // the 6D local rotations, the root positions and the offsets (double precision).
  const Skeleton skel = test::small_skeleton();
  const int B = 2, T = 2, J = skel.num_joints();
  std::vector<at::Tensor> rots, roots;
  for (int b = 0; b < B; ++b) {
    const Motion m = test::random_motion(skel, T, 30.0, 900 + b);
    rots.push_back(torch_rot::quat_to_matrix(motion_quats(m, at::kDouble)));
    roots.push_back(motion_roots(m, at::kDouble));
  }
  torch::manual_seed(3);
  // Perturbed so that the 6D inputs are not exactly orthonormal.
  at::Tensor d6 = (torch_rot::matrix_to_sixd(torch::stack(rots)) + 0.1 * torch::randn({B, T, J, 6}, torch::kDouble))
                      .detach()
                      .requires_grad_(true);
  at::Tensor root = torch::stack(roots).detach().requires_grad_(true);
  at::Tensor offsets = offsets_tensor(skel).to(torch::kDouble).requires_grad_(true);
  const at::Tensor weights = torch::randn({B, T, J, 3}, torch::kDouble);
  const at::Tensor rot_weights = torch::randn({B, T, J, 3, 3}, torch::kDouble);
  auto loss = [&](const at::Tensor& x6, const at::Tensor& r, const at::Tensor& o) {
    FkTensors fk = forward_kinematics(skel.parents, o, torch_rot::sixd_to_matrix(x6), r);
    return (fk.positions * weights).sum() + (fk.rotations * rot_weights).sum();
  };
  loss(d6, root, offsets).backward();
  const at::Tensor x6 = d6.detach(), r = root.detach(), o = offsets.detach();
  test::expect_gradient_matches_finite_differences([&](const at::Tensor& x) { return loss(x, r, o); }, d6,
                                                   "6D rotations");
  test::expect_gradient_matches_finite_differences([&](const at::Tensor& x) { return loss(x6, x, o); }, root,
                                                   "root positions");
  test::expect_gradient_matches_finite_differences([&](const at::Tensor& x) { return loss(x6, r, x); }, offsets,
                                                   "offsets");
  // The root's offset row does not influence anything.
  EXPECT_LT(offsets.grad()[0].abs().max().item<double>(), 1e-15);
}

TEST(KinematicsTorch, GradientsWhenOnlyPositionsAreUsedAndTheRootIsShared) {
  // The rotations output unused (its gradient undefined in the backward) and one
  // root path shared by two windows (its gradient summed over them): checked
  // against central differences in double precision.
  const Skeleton skel = test::small_skeleton();
  const int B = 2, T = 3, J = skel.num_joints();
  torch::manual_seed(5);
  at::Tensor d6 = torch::randn({B, T, J, 6}, torch::kDouble).requires_grad_(true);
  at::Tensor root = torch::randn({T, 3}, torch::kDouble).requires_grad_(true);
  const at::Tensor offsets = offsets_tensor(skel).to(torch::kDouble);
  const at::Tensor weights = torch::randn({B, T, J, 3}, torch::kDouble);
  auto loss = [&](const at::Tensor& x6, const at::Tensor& r) {
    return (forward_kinematics(skel.parents, offsets, torch_rot::sixd_to_matrix(x6), r).positions * weights).sum();
  };
  loss(d6, root).backward();
  // Every 7th entry keeps the test fast.
  test::expect_gradient_matches_finite_differences([&](const at::Tensor& x) { return loss(x, root.detach()); }, d6,
                                                   "6D", 1e-6, 1e-6, 7);
  test::expect_gradient_matches_finite_differences([&](const at::Tensor& x) { return loss(d6.detach(), x); }, root,
                                                   "root", 1e-6, 1e-6, 7);
}

TEST(KinematicsTorch, OffsetsTensor) {
  const Skeleton skel = test::small_skeleton();
  at::Tensor o = offsets_tensor(skel);
  ASSERT_EQ(o.sizes(), (at::IntArrayRef{skel.num_joints(), 3}));
  EXPECT_EQ(o.scalar_type(), torch::kFloat);
  for (int j = 0; j < skel.num_joints(); ++j)
    for (int k = 0; k < 3; ++k) EXPECT_FLOAT_EQ(o[j][k].item<float>(), static_cast<float>(skel.offsets[j][k]));
}

TEST(KinematicsTorch, BadInputThrowsInputError) {
  const std::vector<int> parents = {-1, 0, 1};
  const at::Tensor offsets = torch::zeros({3, 3});
  const at::Tensor local = torch::eye(3).expand({5, 3, 3, 3});
  const at::Tensor root = torch::zeros({5, 3});
  EXPECT_NO_THROW(forward_kinematics(parents, offsets, local, root));
  EXPECT_THROW(forward_kinematics({}, offsets, local, root), InputError);
  EXPECT_THROW(forward_kinematics({-1, 0}, offsets, local, root), InputError);         // J mismatch
  EXPECT_THROW(forward_kinematics({0, 0, 1}, offsets, local, root), InputError);       // root not -1
  EXPECT_THROW(forward_kinematics({-1, 2, 1}, offsets, local, root), InputError);      // parent after child
  EXPECT_THROW(forward_kinematics({-1, -1, 1}, offsets, local, root), InputError);     // second root
  EXPECT_THROW(forward_kinematics(parents, torch::zeros({3, 2}), local, root), InputError);
  EXPECT_THROW(forward_kinematics(parents, offsets, torch::zeros({5, 3, 3}), root), InputError);
  EXPECT_THROW(forward_kinematics(parents, offsets, local, torch::zeros({5, 2})), InputError);
  EXPECT_THROW(forward_kinematics(parents, offsets, local, torch::zeros({4, 3})), InputError);  // no broadcast
}

TEST(KinematicsTorch, IdentityPoseIsRestPose) {
  // With identity rotations every joint sits at the sum of offsets along its chain.
  const Skeleton skel = test::small_skeleton();
  const int J = skel.num_joints();
  at::Tensor local = torch::eye(3).expand({J, 3, 3});
  FkTensors fk = forward_kinematics(skel.parents, offsets_tensor(skel), local, torch::zeros({3}));
  for (int j = 0; j < J; ++j) {
    Eigen::Vector3d expected = Eigen::Vector3d::Zero();
    for (int k = j; k > 0; k = skel.parents[k]) expected += skel.offsets[k];
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(fk.positions[j][c].item<double>(), expected[c], 1e-6) << j;
  }
}

}  // namespace
}  // namespace mf
