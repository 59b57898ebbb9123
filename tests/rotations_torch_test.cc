// Tests of the batched torch rotation functions: hand-computed cases, the
// double cover, gradients at the singular-looking points (identity, 180
// degrees), and cross-checks against the Eigen versions in rotations.h.
#include "prior/motion/rotations_torch.h"

#include <gtest/gtest.h>
#include <torch/types.h>

#include <cmath>
#include <random>
#include <vector>

#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "tests/gradient_check.h"
#include "tests/test_util.h"

namespace mf {
namespace {

using namespace mf::torch_rot;

constexpr double kPi = 3.14159265358979323846;

at::Tensor quat_tensor(const Eigen::Quaterniond& q, at::ScalarType dtype = at::kFloat) {
  return torch::tensor({q.w(), q.x(), q.y(), q.z()}, torch::kDouble).to(dtype);
}

at::Tensor matrix_tensor(const Eigen::Matrix3d& m, at::ScalarType dtype = at::kFloat) {
  at::Tensor t = torch::empty({3, 3}, torch::kDouble);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) t[r][c] = m(r, c);
  return t.to(dtype);
}

Eigen::Matrix3d to_matrix(const at::Tensor& t) {
  at::Tensor d = t.detach().to(torch::kDouble).contiguous();
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = d[r][c].item<double>();
  return m;
}

Eigen::Quaterniond to_quat(const at::Tensor& t) {
  at::Tensor d = t.detach().to(torch::kDouble).contiguous();
  return Eigen::Quaterniond(d[0].item<double>(), d[1].item<double>(), d[2].item<double>(), d[3].item<double>());
}

double max_abs_diff(const at::Tensor& a, const at::Tensor& b) {
  return (a.detach().to(torch::kDouble) - b.detach().to(torch::kDouble)).abs().max().item<double>();
}

// Equal as rotations: q or -q.
double quat_sign_free_diff(const at::Tensor& a, const at::Tensor& b) {
  return std::min(max_abs_diff(a, b), max_abs_diff(a, -b));
}

bool all_finite(const at::Tensor& t) { return torch::isfinite(t).all().item<bool>(); }

Eigen::Quaterniond axis_angle(double angle, const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis.normalized()));
}

std::vector<Eigen::Quaterniond> random_quats(int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Eigen::Quaterniond> out;
  for (int i = 0; i < n; ++i) {
    Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
    out.push_back(q.normalized());
  }
  return out;
}

at::Tensor stack_quats(const std::vector<Eigen::Quaterniond>& qs, at::ScalarType dtype = at::kFloat) {
  std::vector<at::Tensor> ts;
  for (const auto& q : qs) ts.push_back(quat_tensor(q, dtype));
  return torch::stack(ts);
}

// The 90-degree rotations about X, Y and Z, written out by hand.
const Eigen::Matrix3d& rot90(int axis) {
  static const Eigen::Matrix3d m[3] = {
      (Eigen::Matrix3d() << 1, 0, 0, 0, 0, -1, 0, 1, 0).finished(),
      (Eigen::Matrix3d() << 0, 0, 1, 0, 1, 0, -1, 0, 0).finished(),
      (Eigen::Matrix3d() << 0, -1, 0, 1, 0, 0, 0, 0, 1).finished()};
  return m[axis];
}

TEST(RotationsTorch, QuatToMatrix90DegreesAboutEachAxis) {
  const double h = std::sqrt(0.5);
  for (int axis = 0; axis < 3; ++axis) {
    Eigen::Quaterniond q(h, axis == 0 ? h : 0, axis == 1 ? h : 0, axis == 2 ? h : 0);
    at::Tensor m = quat_to_matrix(quat_tensor(q));
    EXPECT_EQ(m.sizes(), (at::IntArrayRef{3, 3}));
    EXPECT_LT(max_abs_diff(m, matrix_tensor(rot90(axis))), 1e-6) << "axis " << axis;
    // And back: w >= 0 picks the sign.
    EXPECT_LT(max_abs_diff(matrix_to_quat(matrix_tensor(rot90(axis))), quat_tensor(q)), 1e-6) << "axis " << axis;
  }
}

TEST(RotationsTorch, QuatRotateHandCases) {
  const double h = std::sqrt(0.5);
  // 90 degrees about Z takes x to y; about X takes y to z; about Y takes z to x.
  at::Tensor qz = torch::tensor({h, 0.0, 0.0, h}, torch::kFloat);
  at::Tensor qx = torch::tensor({h, h, 0.0, 0.0}, torch::kFloat);
  at::Tensor qy = torch::tensor({h, 0.0, h, 0.0}, torch::kFloat);
  EXPECT_LT(max_abs_diff(quat_rotate(qz, torch::tensor({1.0f, 0.0f, 0.0f})), torch::tensor({0.0, 1.0, 0.0})), 1e-6);
  EXPECT_LT(max_abs_diff(quat_rotate(qx, torch::tensor({0.0f, 1.0f, 0.0f})), torch::tensor({0.0, 0.0, 1.0})), 1e-6);
  EXPECT_LT(max_abs_diff(quat_rotate(qy, torch::tensor({0.0f, 0.0f, 1.0f})), torch::tensor({1.0, 0.0, 0.0})), 1e-6);
  // 180 degrees about Y: (1, 2, 3) -> (-1, 2, -3).
  at::Tensor qy180 = torch::tensor({0.0f, 0.0f, 1.0f, 0.0f});
  EXPECT_LT(max_abs_diff(quat_rotate(qy180, torch::tensor({1.0f, 2.0f, 3.0f})), torch::tensor({-1.0, 2.0, -3.0})),
            1e-6);
}

TEST(RotationsTorch, QuatMultiplyAndConjugateHandCases) {
  at::Tensor i = torch::tensor({0.0f, 1.0f, 0.0f, 0.0f});
  at::Tensor j = torch::tensor({0.0f, 0.0f, 1.0f, 0.0f});
  at::Tensor k = torch::tensor({0.0f, 0.0f, 0.0f, 1.0f});
  EXPECT_LT(max_abs_diff(quat_multiply(i, j), k), 1e-7);   // ij = k
  EXPECT_LT(max_abs_diff(quat_multiply(j, i), -k), 1e-7);  // ji = -k
  EXPECT_LT(max_abs_diff(quat_multiply(i, i), torch::tensor({-1.0, 0.0, 0.0, 0.0})), 1e-7);
  EXPECT_LT(max_abs_diff(quat_conjugate(torch::tensor({0.5f, 0.1f, -0.2f, 0.3f})),
                         torch::tensor({0.5, -0.1, 0.2, -0.3})),
            1e-7);
  // Composition matches the matrix product: R(a b) = R(a) R(b).
  const double h = std::sqrt(0.5);
  at::Tensor qx = torch::tensor({h, h, 0.0, 0.0}, torch::kFloat);
  at::Tensor qy = torch::tensor({h, 0.0, h, 0.0}, torch::kFloat);
  EXPECT_LT(max_abs_diff(quat_to_matrix(quat_multiply(qx, qy)), matrix_tensor(rot90(0) * rot90(1))), 1e-6);
  // q q* = identity.
  at::Tensor q = quat_normalize(torch::tensor({0.3f, -0.4f, 0.5f, 0.7f}));
  EXPECT_LT(max_abs_diff(quat_multiply(q, quat_conjugate(q)), torch::tensor({1.0, 0.0, 0.0, 0.0})), 1e-6);
}

TEST(RotationsTorch, QuatNormalizeHandCase) {
  at::Tensor q = quat_normalize(torch::tensor({{2.0f, 0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f, 1.0f}}));
  EXPECT_LT(max_abs_diff(q, torch::tensor({{1.0, 0.0, 0.0, 0.0}, {0.5, 0.5, 0.5, 0.5}})), 1e-7);
  // A zero quaternion does not produce NaN (values or gradients).
  at::Tensor z = torch::zeros({4}, torch::kFloat).requires_grad_(true);
  at::Tensor n = quat_normalize(z);
  n.sum().backward();
  EXPECT_TRUE(all_finite(n));
  EXPECT_TRUE(all_finite(z.grad()));
}

TEST(RotationsTorch, MatrixToQuatHandles180Degrees) {
  // Trace = -1: every 180-degree rotation, including about a diagonal axis.
  std::vector<Eigen::Vector3d> axes = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {1, -2, 3}, {0, 1, -1}};
  for (const auto& a : axes) {
    const Eigen::Vector3d n = a.normalized();
    const Eigen::Matrix3d m = 2.0 * n * n.transpose() - Eigen::Matrix3d::Identity();  // hand formula
    at::Tensor q = matrix_to_quat(matrix_tensor(m));
    at::Tensor expected = torch::tensor({0.0, n.x(), n.y(), n.z()});
    EXPECT_LT(quat_sign_free_diff(q, expected), 1e-6) << a.transpose();
    EXPECT_NEAR(q.norm().item<double>(), 1.0, 1e-6);
    EXPECT_LT(max_abs_diff(quat_to_matrix(q), matrix_tensor(m)), 1e-6) << a.transpose();
  }
  // Axis-aligned hand case: diag(1, -1, -1) is 180 degrees about X.
  at::Tensor q = matrix_to_quat(torch::diag(torch::tensor({1.0f, -1.0f, -1.0f})));
  EXPECT_LT(quat_sign_free_diff(q, torch::tensor({0.0, 1.0, 0.0, 0.0})), 1e-7);
}

TEST(RotationsTorch, MatrixToQuatNearIdentityAndSign) {
  at::Tensor q = matrix_to_quat(torch::eye(3, torch::kFloat));
  EXPECT_LT(max_abs_diff(q, torch::tensor({1.0, 0.0, 0.0, 0.0})), 1e-7);
  // A tiny rotation keeps its axis information (no acos round-off).
  const double angle = 1e-4;
  Eigen::Quaterniond small = axis_angle(angle, {0, 0, 1});
  at::Tensor qs = matrix_to_quat(matrix_tensor(small.toRotationMatrix()));
  EXPECT_NEAR(qs[3].item<double>(), std::sin(angle / 2), 1e-9);
  // w >= 0 for every output, even when the input came from a quaternion with w < 0.
  std::vector<Eigen::Quaterniond> qs_rand = random_quats(200, 7);
  at::Tensor out = matrix_to_quat(quat_to_matrix(stack_quats(qs_rand)));
  EXPECT_TRUE((out.select(-1, 0) >= 0).all().item<bool>());
}

TEST(RotationsTorch, DoubleCover) {
  std::vector<Eigen::Quaterniond> qs = random_quats(50, 11);
  at::Tensor q = stack_quats(qs);
  at::Tensor m_pos = quat_to_matrix(q), m_neg = quat_to_matrix(-q);
  EXPECT_LT(max_abs_diff(m_pos, m_neg), 1e-6);
  EXPECT_LT(geodesic_angle(m_pos, m_neg).abs().max().item<double>(), 1e-3);
  // matrix_to_quat picks one representative for both.
  EXPECT_LT(max_abs_diff(matrix_to_quat(m_pos), matrix_to_quat(m_neg)), 1e-6);
  // Rotating a vector does not depend on the sign either.
  at::Tensor v = torch::randn({50, 3}, torch::kFloat);
  EXPECT_LT(max_abs_diff(quat_rotate(q, v), quat_rotate(-q, v)), 1e-5);
}

TEST(RotationsTorch, SixdHandCases) {
  Eigen::Matrix3d m;
  m << 1, 2, 3, 4, 5, 6, 7, 8, 9;  // not a rotation: only the layout is checked
  EXPECT_LT(max_abs_diff(matrix_to_sixd(matrix_tensor(m)), torch::tensor({1.0, 4.0, 7.0, 2.0, 5.0, 8.0})), 1e-7);
  // Gram-Schmidt on a non-orthonormal input: a1 = (2, 0, 0), a2 = (1, 3, 0).
  at::Tensor r = sixd_to_matrix(torch::tensor({2.0f, 0.0f, 0.0f, 1.0f, 3.0f, 0.0f}));
  EXPECT_LT(max_abs_diff(r, torch::eye(3)), 1e-7);
  // a1 = (0, 0, 5), a2 = (1, 0, 1): b1 = z, b2 = x, b3 = z x x = y.
  at::Tensor r2 = sixd_to_matrix(torch::tensor({0.0f, 0.0f, 5.0f, 1.0f, 0.0f, 1.0f}));
  Eigen::Matrix3d expected;
  expected << 0, 1, 0, 0, 0, 1, 1, 0, 0;
  EXPECT_LT(max_abs_diff(r2, matrix_tensor(expected)), 1e-7);
  // Round trip on rotations.
  for (int axis = 0; axis < 3; ++axis)
    EXPECT_LT(max_abs_diff(sixd_to_matrix(matrix_to_sixd(matrix_tensor(rot90(axis)))), matrix_tensor(rot90(axis))),
              1e-7);
}

TEST(RotationsTorch, SlerpHandCases) {
  at::Tensor id = torch::tensor({1.0f, 0.0f, 0.0f, 0.0f});
  at::Tensor z90 = quat_tensor(axis_angle(kPi / 2, {0, 0, 1}));
  at::Tensor half = torch::tensor({0.5f});
  EXPECT_LT(max_abs_diff(quat_slerp(id, z90, half), quat_tensor(axis_angle(kPi / 4, {0, 0, 1}))), 1e-6);
  EXPECT_LT(max_abs_diff(quat_slerp(id, z90, torch::tensor({0.25f})), quat_tensor(axis_angle(kPi / 8, {0, 0, 1}))),
            1e-6);
  EXPECT_LT(quat_sign_free_diff(quat_slerp(id, z90, torch::tensor({0.0f})), id), 1e-6);
  EXPECT_LT(quat_sign_free_diff(quat_slerp(id, z90, torch::tensor({1.0f})), z90), 1e-6);
  // Shortest path: -z90 is the same rotation, the result is the same up to sign.
  EXPECT_LT(quat_sign_free_diff(quat_slerp(id, -z90, half), quat_tensor(axis_angle(kPi / 4, {0, 0, 1}))), 1e-6);
  // Nearly equal inputs (nlerp fallback) stay unit and finite.
  at::Tensor tiny = quat_tensor(axis_angle(1e-5, {1, 0, 0}));
  at::Tensor mid = quat_slerp(id, tiny, half);
  EXPECT_NEAR(mid.norm().item<double>(), 1.0, 1e-6);
  EXPECT_LT(max_abs_diff(mid, quat_tensor(axis_angle(0.5e-5, {1, 0, 0}))), 1e-6);
}

TEST(RotationsTorch, SlerpBroadcastsTime) {
  // Two quaternion pairs, five times each: t [5, 1, 1] against q [2, 4].
  at::Tensor q0 = stack_quats(random_quats(2, 3));
  at::Tensor q1 = stack_quats(random_quats(2, 4));
  at::Tensor t = torch::linspace(0, 1, 5).view({5, 1, 1});
  at::Tensor out = quat_slerp(q0, q1, t);
  EXPECT_EQ(out.sizes(), (at::IntArrayRef{5, 2, 4}));
  EXPECT_LT(quat_sign_free_diff(out[0], q0), 1e-6);
  EXPECT_LT(quat_sign_free_diff(out[4], q1), 1e-6);
}

TEST(RotationsTorch, GeodesicHandCases) {
  at::Tensor id = torch::eye(3);
  EXPECT_NEAR(geodesic_angle(id, id).item<double>(), 0.0, 1e-7);
  for (int axis = 0; axis < 3; ++axis)
    EXPECT_NEAR(geodesic_angle(id, matrix_tensor(rot90(axis))).item<double>(), kPi / 2, 1e-6);
  EXPECT_NEAR(geodesic_angle(id, torch::diag(torch::tensor({1.0f, -1.0f, -1.0f}))).item<double>(), kPi, 1e-6);
  // Symmetric and relative: angle(A, A R) = angle(R).
  Eigen::Matrix3d a = random_quats(1, 5)[0].toRotationMatrix();
  Eigen::Matrix3d r = axis_angle(0.7, {1, 2, 3}).toRotationMatrix();
  EXPECT_NEAR(geodesic_angle(matrix_tensor(a), matrix_tensor(a * r)).item<double>(), 0.7, 1e-5);
  EXPECT_NEAR(geodesic_angle(matrix_tensor(a * r), matrix_tensor(a)).item<double>(), 0.7, 1e-5);
  // Small angles keep their relative precision in float.
  Eigen::Matrix3d s = axis_angle(1e-3, {0, 1, 0}).toRotationMatrix();
  EXPECT_NEAR(geodesic_angle(id, matrix_tensor(s)).item<double>(), 1e-3, 1e-7);
}

TEST(RotationsTorch, GeodesicGradientsFiniteAtIdentityAnd180) {
  for (auto dtype : {torch::kFloat, torch::kDouble}) {
    Eigen::Matrix3d base = axis_angle(0.4, {1, -1, 2}).toRotationMatrix();
    // Identical inputs.
    {
      at::Tensor m0 = matrix_tensor(base, dtype).requires_grad_(true);
      at::Tensor m1 = matrix_tensor(base, dtype).requires_grad_(true);
      geodesic_angle(m0, m1).backward();
      EXPECT_TRUE(all_finite(m0.grad()));
      EXPECT_TRUE(all_finite(m1.grad()));
    }
    // Exactly 180 degrees, identity against diag(1, -1, -1) and about a diagonal axis.
    for (const Eigen::Vector3d& axis : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 1)}) {
      const Eigen::Vector3d n = axis.normalized();
      at::Tensor m0 = torch::eye(3, dtype).requires_grad_(true);
      at::Tensor m1 = matrix_tensor(2.0 * n * n.transpose() - Eigen::Matrix3d::Identity(), dtype).requires_grad_(true);
      at::Tensor angle = geodesic_angle(m0, m1);
      EXPECT_NEAR(angle.item<double>(), kPi, 1e-6);
      angle.backward();
      EXPECT_TRUE(all_finite(m0.grad()));
      EXPECT_TRUE(all_finite(m1.grad()));
    }
    // The training path: 6D -> matrix -> geodesic against the same rotation.
    {
      at::Tensor d6 = matrix_to_sixd(matrix_tensor(base, dtype)).detach().requires_grad_(true);
      geodesic_angle(sixd_to_matrix(d6), matrix_tensor(base, dtype)).backward();
      EXPECT_TRUE(all_finite(d6.grad()));
    }
  }
}

TEST(RotationsTorch, SixdGradientMatchesFiniteDifferences) {
  // Every entry of the matrix weighted, on non-orthonormal inputs of several scales
  // (double precision), and a zero 6D vector: finite values and gradients.
  torch::manual_seed(11);
  at::Tensor d6 = (torch::randn({5, 6}, torch::kDouble) * torch::tensor({0.1, 1.0, 3.0, 1.0, 20.0}, torch::kDouble)
                                                              .unsqueeze(-1))
                      .requires_grad_(true);
  const at::Tensor w = torch::randn({5, 3, 3}, torch::kDouble);
  auto f = [&](const at::Tensor& x) { return (sixd_to_matrix(x) * w).sum(); };
  f(d6).backward();
  test::expect_gradient_matches_finite_differences(f, d6, "6D");
  at::Tensor zero = torch::zeros({1, 6}, torch::kFloat).requires_grad_(true);
  at::Tensor m = sixd_to_matrix(zero);
  m.sum().backward();
  EXPECT_TRUE(torch::isfinite(m).all().item<bool>());
  EXPECT_TRUE(torch::isfinite(zero.grad()).all().item<bool>());
}

TEST(RotationsTorch, GeodesicGradientMatchesFiniteDifferences) {
  // Away from the singular points the gradient is the ordinary derivative.
  at::Tensor d6 = torch::tensor({0.9, 0.3, -0.2, -0.1, 0.8, 0.4}, torch::kDouble).requires_grad_(true);
  at::Tensor target = matrix_tensor(axis_angle(2.0, {0.3, 1, -0.5}).toRotationMatrix(), torch::kDouble);
  auto f = [&](const at::Tensor& x) { return geodesic_angle(sixd_to_matrix(x), target); };
  f(d6).backward();
  test::expect_gradient_matches_finite_differences(f, d6, "6D");
}

TEST(RotationsTorch, GeodesicNodeGradientMatchesFiniteDifferencesOnAnyMatrices) {
  // The node's backward is the derivative of its own forward, atan2(|skew|, (trace - 1) / 2)
  // of m0^T m1, for any matrices (here not rotations), in both arguments.
  torch::manual_seed(5);
  at::Tensor m0 = torch::randn({4, 3, 3}, torch::kDouble).requires_grad_(true);
  at::Tensor m1 = torch::randn({4, 3, 3}, torch::kDouble).requires_grad_(true);
  const at::Tensor w = torch::randn({4}, torch::kDouble);
  auto f = [&](const at::Tensor& a, const at::Tensor& b) { return (geodesic_angle(a, b) * w).sum(); };
  f(m0, m1).backward();
  test::expect_gradient_matches_finite_differences([&](const at::Tensor& x) { return f(x, m1.detach()); }, m0, "m0");
  test::expect_gradient_matches_finite_differences([&](const at::Tensor& x) { return f(m0.detach(), x); }, m1, "m1");
}

TEST(RotationsTorch, GeodesicMatchesTheQuaternionRouteOnRotations) {
  // On rotations the node equals 2 atan2(|xyz|, |w|) of matrix_to_quat(m0^T m1), in value
  // and in the gradient with respect to 6D inputs (the directions a decode can move).
  torch::manual_seed(9);
  at::Tensor d6 = torch::randn({64, 6}, torch::kDouble).requires_grad_(true);
  const at::Tensor target = quat_to_matrix(stack_quats(random_quats(64, 21), at::kDouble));
  auto quat_route = [&](const at::Tensor& m0, const at::Tensor& m1) {
    at::Tensor q = matrix_to_quat(matmul3(m0.transpose(-1, -2), m1));
    return 2 * at::atan2(q.narrow(-1, 1, 3).norm(2, -1), q.select(-1, 0).abs());
  };
  at::Tensor node = geodesic_angle(sixd_to_matrix(d6), target);
  node.square().sum().backward();
  const at::Tensor node_grad = d6.grad().clone();
  d6.grad().zero_();
  at::Tensor reference = quat_route(sixd_to_matrix(d6), target);
  reference.square().sum().backward();
  EXPECT_LT(max_abs_diff(node, reference), 1e-9);
  EXPECT_LT(max_abs_diff(node_grad, d6.grad()), 1e-8);
  // Broadcasting: one target against a batch, float in and out.
  at::Tensor batch = quat_to_matrix(stack_quats(random_quats(5, 22)));
  at::Tensor one = quat_to_matrix(stack_quats(random_quats(1, 23))).squeeze(0);
  at::Tensor out = geodesic_angle(batch, one);
  EXPECT_EQ(out.sizes(), (at::IntArrayRef{5}));
  EXPECT_EQ(out.scalar_type(), torch::kFloat);
  EXPECT_LT(max_abs_diff(out, quat_route(batch, one.expand({5, 3, 3}))), 1e-5);
  EXPECT_THROW(geodesic_angle(torch::eye(3, torch::kLong), torch::eye(3)), InputError);
}

TEST(RotationsTorch, MatrixToQuatGradientsFiniteAt180) {
  at::Tensor m = torch::diag(torch::tensor({-1.0, -1.0, 1.0}, torch::kDouble)).requires_grad_(true);
  matrix_to_quat(m).sum().backward();
  EXPECT_TRUE(all_finite(m.grad()));
  at::Tensor e = torch::eye(3, torch::kDouble).requires_grad_(true);
  matrix_to_quat(e).sum().backward();
  EXPECT_TRUE(all_finite(e.grad()));
}

TEST(RotationsTorch, SlerpGradientsFiniteForEqualInputs) {
  at::Tensor q0 = quat_tensor(axis_angle(0.3, {1, 0, 0})).requires_grad_(true);
  at::Tensor q1 = quat_tensor(axis_angle(0.3, {1, 0, 0})).requires_grad_(true);
  at::Tensor t = torch::tensor({0.3f}).requires_grad_(true);
  quat_slerp(q0, q1, t).sum().backward();
  EXPECT_TRUE(all_finite(q0.grad()));
  EXPECT_TRUE(all_finite(q1.grad()));
  EXPECT_TRUE(all_finite(t.grad()));
}

TEST(RotationsTorch, MakeContinuous) {
  // Along dim 0 of [T, 4]: flips whenever the sign jumps, relative to the previous output.
  at::Tensor q = quat_tensor(axis_angle(0.1, {0, 1, 0}));
  at::Tensor seq = torch::stack({q, -q, -q, q, -q});
  at::Tensor out = quat_make_continuous(seq, 0);
  for (int i = 0; i < 5; ++i) EXPECT_LT(max_abs_diff(out[i], q), 1e-7) << i;
  // The first element keeps its sign.
  at::Tensor out_neg = quat_make_continuous(-seq, 0);
  for (int i = 0; i < 5; ++i) EXPECT_LT(max_abs_diff(out_neg[i], -q), 1e-7) << i;
  // Along the time dimension of [B, T, 4] with a negative index; batches are independent.
  at::Tensor batch = torch::stack({seq, -seq});  // [2, 5, 4]
  at::Tensor out_b = quat_make_continuous(batch, -2);
  EXPECT_EQ(out_b.sizes(), batch.sizes());
  for (int i = 0; i < 5; ++i) {
    EXPECT_LT(max_abs_diff(out_b[0][i], q), 1e-7);
    EXPECT_LT(max_abs_diff(out_b[1][i], -q), 1e-7);
  }
  // Along a dimension of length 1, and gradients flow through the values.
  at::Tensor x = seq.clone().requires_grad_(true);
  quat_make_continuous(x, 0).sum().backward();
  EXPECT_LT(max_abs_diff(x.grad().select(-1, 0), torch::tensor({1.0, -1.0, -1.0, 1.0, -1.0})), 1e-7);
  EXPECT_EQ(quat_make_continuous(seq.unsqueeze(0), 0).sizes(), (at::IntArrayRef{1, 5, 4}));
  EXPECT_THROW(quat_make_continuous(seq, 1), InputError);   // the quaternion dimension itself
  EXPECT_THROW(quat_make_continuous(seq, -1), InputError);
  EXPECT_THROW(quat_make_continuous(seq, 2), InputError);
}

TEST(RotationsTorch, BatchedShapesAndDtype) {
  const int64_t B = 2, T = 3, J = 4;
  at::Tensor q = quat_normalize(torch::randn({B, T, J, 4}, torch::kFloat));
  at::Tensor m = quat_to_matrix(q);
  EXPECT_EQ(m.sizes(), (at::IntArrayRef{B, T, J, 3, 3}));
  EXPECT_EQ(matrix_to_quat(m).sizes(), (at::IntArrayRef{B, T, J, 4}));
  EXPECT_EQ(matrix_to_sixd(m).sizes(), (at::IntArrayRef{B, T, J, 6}));
  EXPECT_EQ(sixd_to_matrix(matrix_to_sixd(m)).sizes(), (at::IntArrayRef{B, T, J, 3, 3}));
  EXPECT_EQ(geodesic_angle(m, m).sizes(), (at::IntArrayRef{B, T, J}));
  EXPECT_EQ(quat_rotate(q, torch::randn({J, 3})).sizes(), (at::IntArrayRef{B, T, J, 3}));  // broadcast
  EXPECT_EQ(quat_multiply(q, q[0][0]).sizes(), (at::IntArrayRef{B, T, J, 4}));
  EXPECT_EQ(quat_slerp(q, q, torch::full({B, T, J, 1}, 0.5f)).sizes(), (at::IntArrayRef{B, T, J, 4}));
  // Batched results equal element-wise ones.
  EXPECT_LT(max_abs_diff(quat_to_matrix(q)[1][2][3], quat_to_matrix(q[1][2][3])), 1e-7);
  EXPECT_LT(max_abs_diff(matrix_to_quat(m)[1][0][2], matrix_to_quat(m[1][0][2])), 1e-7);
  // Dtype follows the input.
  at::Tensor qd = q.to(torch::kDouble);
  EXPECT_EQ(quat_to_matrix(qd).scalar_type(), torch::kDouble);
  EXPECT_EQ(matrix_to_quat(quat_to_matrix(qd)).scalar_type(), torch::kDouble);
  EXPECT_EQ(geodesic_angle(quat_to_matrix(qd), quat_to_matrix(qd)).scalar_type(), torch::kDouble);
  EXPECT_EQ(sixd_to_matrix(matrix_to_sixd(quat_to_matrix(qd))).scalar_type(), torch::kDouble);
}

TEST(RotationsTorch, BadShapesThrowInputError) {
  EXPECT_THROW(quat_normalize(torch::zeros({3})), InputError);
  EXPECT_THROW(quat_multiply(torch::zeros({4}), torch::zeros({3})), InputError);
  EXPECT_THROW(quat_rotate(torch::zeros({4}), torch::zeros({4})), InputError);
  EXPECT_THROW(quat_to_matrix(torch::zeros({2, 3})), InputError);
  EXPECT_THROW(matrix_to_quat(torch::zeros({3, 4})), InputError);
  EXPECT_THROW(matrix_to_quat(torch::zeros({3})), InputError);
  EXPECT_THROW(matrix_to_sixd(torch::zeros({2, 3})), InputError);
  EXPECT_THROW(sixd_to_matrix(torch::zeros({5})), InputError);
  EXPECT_THROW(geodesic_angle(torch::eye(3), torch::zeros({3, 2})), InputError);
  EXPECT_THROW(quat_slerp(torch::zeros({4}), torch::zeros({4}), at::Tensor()), InputError);
  EXPECT_THROW(quat_conjugate(at::Tensor()), InputError);
}

// ---- Cross-checks against the Eigen (double) implementations ----

TEST(RotationsTorch, MatchesEigenConversions) {
  std::vector<Eigen::Quaterniond> qs = random_quats(300, 21);
  at::Tensor q = stack_quats(qs);
  at::Tensor m = quat_to_matrix(q);
  at::Tensor back = matrix_to_quat(m);
  at::Tensor d6 = matrix_to_sixd(m);
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  for (size_t i = 0; i < qs.size(); ++i) {
    const Eigen::Matrix3d em = qs[i].toRotationMatrix();
    EXPECT_LT((to_matrix(m[i]) - em).cwiseAbs().maxCoeff(), 1e-5) << i;
    EXPECT_LT(std::min((to_quat(back[i]).coeffs() - qs[i].coeffs()).cwiseAbs().maxCoeff(),
                       (to_quat(back[i]).coeffs() + qs[i].coeffs()).cwiseAbs().maxCoeff()),
              1e-5)
        << i;
    const Vector6d e6 = sixd_from_matrix(em);
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(d6[i][k].item<double>(), e6[k], 1e-5) << i;
    // Gram-Schmidt on a perturbed (non-orthonormal) 6-vector.
    Vector6d noisy = e6;
    for (int k = 0; k < 6; ++k) noisy[k] = 1.5 * noisy[k] + 0.2 * g(rng);
    at::Tensor nt = torch::empty({6}, torch::kDouble);
    for (int k = 0; k < 6; ++k) nt[k] = noisy[k];
    EXPECT_LT((to_matrix(sixd_to_matrix(nt.to(torch::kFloat))) - matrix_from_sixd(noisy)).cwiseAbs().maxCoeff(), 1e-5)
        << i;
  }
}

TEST(RotationsTorch, MatchesEigenProductsAndRotation) {
  std::vector<Eigen::Quaterniond> a = random_quats(200, 31), b = random_quats(200, 32);
  at::Tensor prod = quat_multiply(stack_quats(a), stack_quats(b));
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  std::vector<Eigen::Vector3d> vs;
  at::Tensor v = torch::empty({200, 3}, torch::kDouble);
  for (int i = 0; i < 200; ++i) {
    vs.emplace_back(u(rng), u(rng), u(rng));
    for (int k = 0; k < 3; ++k) v[i][k] = vs.back()[k];
  }
  at::Tensor rotated = quat_rotate(stack_quats(a), v.to(torch::kFloat));
  at::Tensor conj = quat_conjugate(stack_quats(a));
  for (int i = 0; i < 200; ++i) {
    EXPECT_LT((to_quat(prod[i]).coeffs() - (a[i] * b[i]).coeffs()).cwiseAbs().maxCoeff(), 1e-5) << i;
    const Eigen::Vector3d ev = a[i] * vs[i];
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(rotated[i][k].item<double>(), ev[k], 1e-5) << i;
    EXPECT_LT((to_quat(conj[i]).coeffs() - a[i].conjugate().coeffs()).cwiseAbs().maxCoeff(), 1e-7) << i;
  }
}

TEST(RotationsTorch, MatchesEigenEulerBuiltRotations) {
  // Rotations built by quat_from_euler (the BVH path) convert identically.
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> u(-kPi, kPi);
  const EulerOrder orders[] = {euler_order_from_string("ZXY"), euler_order_from_string("XYZ"),
                               euler_order_from_string("YZX")};
  for (const auto& order : orders) {
    for (int i = 0; i < 50; ++i) {
      const Eigen::Vector3d angles(u(rng), u(rng), u(rng));
      const Eigen::Quaterniond q = quat_from_euler(angles, order);
      // Composing per-axis torch quaternions in channel order gives the same rotation.
      at::Tensor tq = torch::tensor({1.0f, 0.0f, 0.0f, 0.0f});
      for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d axis = Eigen::Vector3d::Zero();
        axis[static_cast<int>(order[k])] = 1.0;
        tq = quat_multiply(tq, quat_tensor(axis_angle(angles[k], axis)));
      }
      EXPECT_LT(quat_sign_free_diff(tq, quat_tensor(q)), 1e-5);
      EXPECT_LT((to_matrix(quat_to_matrix(tq)) - q.toRotationMatrix()).cwiseAbs().maxCoeff(), 1e-5);
    }
  }
}

TEST(RotationsTorch, MatchesEigenSlerp) {
  std::vector<Eigen::Quaterniond> a = random_quats(200, 51), b = random_quats(200, 52);
  // Include nearly equal pairs (the nlerp branch) and opposite-sign pairs.
  for (int i = 0; i < 20; ++i) b[i] = (a[i] * axis_angle(1e-3 * (i + 1), {1, 2, 3})).normalized();
  for (int i = 20; i < 40; ++i) b[i].coeffs() = -b[i].coeffs();
  std::mt19937 rng(53);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> ts;
  at::Tensor t = torch::empty({200, 1}, torch::kDouble);
  for (int i = 0; i < 200; ++i) {
    ts.push_back(u(rng));
    t[i][0] = ts.back();
  }
  at::Tensor out = quat_slerp(stack_quats(a), stack_quats(b), t.to(torch::kFloat));
  for (int i = 0; i < 200; ++i) {
    const Eigen::Quaterniond e = slerp(a[i], b[i], ts[i]);
    const Eigen::Quaterniond o = to_quat(out[i]);
    EXPECT_LT(std::min((o.coeffs() - e.coeffs()).cwiseAbs().maxCoeff(), (o.coeffs() + e.coeffs()).cwiseAbs().maxCoeff()),
              1e-5)
        << i;
  }
}

TEST(RotationsTorch, MatchesEigenGeodesic) {
  std::vector<Eigen::Quaterniond> a = random_quats(300, 61), b = random_quats(300, 62);
  for (int i = 0; i < 20; ++i) b[i] = (a[i] * axis_angle(1e-3 * (i + 1), {0, 1, 0})).normalized();  // small
  for (int i = 20; i < 30; ++i) b[i] = a[i] * axis_angle(kPi - 1e-3 * (i - 19), {1, 0, 1});             // near pi
  at::Tensor out = geodesic_angle(quat_to_matrix(stack_quats(a)), quat_to_matrix(stack_quats(b)));
  for (int i = 0; i < 300; ++i) EXPECT_NEAR(out[i].item<double>(), geodesic_angle(a[i], b[i]), 1e-5) << i;
  // Double precision inputs agree to near double precision.
  at::Tensor outd = geodesic_angle(quat_to_matrix(stack_quats(a, torch::kDouble)),
                                   quat_to_matrix(stack_quats(b, torch::kDouble)));
  for (int i = 0; i < 300; ++i) EXPECT_NEAR(outd[i].item<double>(), geodesic_angle(a[i], b[i]), 1e-9) << i;
}

}  // namespace
}  // namespace mf
