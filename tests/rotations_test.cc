// Tests of the double-precision rotation conversions (prior/motion/rotations.h)
// against hand-computed cases.
#include "prior/motion/rotations.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "prior/motion/errors.h"

namespace mf {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kHalfSqrt2 = 0.70710678118654752440;

const char* const kOrders[] = {"XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"};

Eigen::Vector3d unit(Axis a) { return Eigen::Vector3d::Unit(static_cast<int>(a)); }

Eigen::Quaterniond random_quat(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  return q.normalized();
}

TEST(RotationsTest, ParsesEulerOrders) {
  EXPECT_EQ(euler_order_from_string("ZXY"), (EulerOrder{Axis::Z, Axis::X, Axis::Y}));
  EXPECT_EQ(euler_order_from_string("xyz"), (EulerOrder{Axis::X, Axis::Y, Axis::Z}));
  EXPECT_EQ(to_string(EulerOrder{Axis::Y, Axis::Z, Axis::X}), "YZX");
  for (const char* s : kOrders) EXPECT_EQ(to_string(euler_order_from_string(s)), s);
  EXPECT_THROW(euler_order_from_string("ZZY"), InputError);
  EXPECT_THROW(euler_order_from_string("XY"), InputError);
  EXPECT_THROW(euler_order_from_string("XYZX"), InputError);
  EXPECT_THROW(euler_order_from_string("XYW"), InputError);
  EXPECT_THROW(euler_order_from_string(""), InputError);
}

// 90 degrees about X, Y and Z in every slot of every order is the plain axis
// rotation: (cos 45, sin 45 * axis).
TEST(RotationsTest, NinetyDegreesAboutEachAxisInEachSlot) {
  for (const char* s : kOrders) {
    const EulerOrder order = euler_order_from_string(s);
    for (int slot = 0; slot < 3; ++slot) {
      Eigen::Vector3d angles = Eigen::Vector3d::Zero();
      angles[slot] = kPi / 2;
      const Eigen::Quaterniond q = quat_from_euler(angles, order);
      const Eigen::Vector3d axis = unit(order[slot]);
      EXPECT_NEAR(q.w(), kHalfSqrt2, 1e-15) << s << " slot " << slot;
      EXPECT_LT((q.vec() - kHalfSqrt2 * axis).norm(), 1e-15) << s << " slot " << slot;

      // And back: the angle lands in its slot, the others stay zero. In the
      // middle slot this is the gimbal lock: third angle 0 by convention.
      const Eigen::Vector3d e = euler_from_quat(q, order);
      EXPECT_LT((e - angles).norm(), 1e-12) << s << " slot " << slot << ": " << e.transpose();
    }
  }
}

// Hand-computed rotations of basis vectors: R_X(90) y = z, R_Y(90) z = x, R_Z(90) x = y.
TEST(RotationsTest, RotatesColumnVectorsActively) {
  const EulerOrder xyz = euler_order_from_string("XYZ");
  EXPECT_LT((quat_from_euler({kPi / 2, 0, 0}, xyz) * Eigen::Vector3d(0, 1, 0) - Eigen::Vector3d(0, 0, 1)).norm(),
            1e-15);
  EXPECT_LT((quat_from_euler({0, kPi / 2, 0}, xyz) * Eigen::Vector3d(0, 0, 1) - Eigen::Vector3d(1, 0, 0)).norm(),
            1e-15);
  EXPECT_LT((quat_from_euler({0, 0, kPi / 2}, xyz) * Eigen::Vector3d(1, 0, 0) - Eigen::Vector3d(0, 1, 0)).norm(),
            1e-15);
}

// BVH order: the first channel is outermost. For ZXY with Z = 90, X = 90:
// R = Rz(90) Rx(90), so z -> Rx: -y -> Rz: x, and y -> Rx: z -> Rz: z.
TEST(RotationsTest, FirstChannelIsOutermost) {
  const Eigen::Quaterniond q = quat_from_euler({kPi / 2, kPi / 2, 0}, euler_order_from_string("ZXY"));
  EXPECT_LT((q * Eigen::Vector3d(0, 0, 1) - Eigen::Vector3d(1, 0, 0)).norm(), 1e-15);
  EXPECT_LT((q * Eigen::Vector3d(0, 1, 0) - Eigen::Vector3d(0, 0, 1)).norm(), 1e-15);
  // The reverse order composes the other way round: Rx(90) Rz(90) z = Rx z = -y.
  const Eigen::Quaterniond r = quat_from_euler({kPi / 2, 0, kPi / 2}, euler_order_from_string("XYZ"));
  EXPECT_LT((r * Eigen::Vector3d(0, 0, 1) - Eigen::Vector3d(0, -1, 0)).norm(), 1e-15);
}

TEST(RotationsTest, RoundTripsRandomRotationsForEveryOrder) {
  std::mt19937 rng(7);
  for (const char* s : kOrders) {
    const EulerOrder order = euler_order_from_string(s);
    for (int n = 0; n < 2000; ++n) {
      const Eigen::Quaterniond q = random_quat(rng);
      const Eigen::Vector3d e = euler_from_quat(q, order);
      ASSERT_LT(geodesic_angle(q, quat_from_euler(e, order)), 1e-12) << s << " " << e.transpose();
      ASSERT_LE(std::abs(e[1]), kPi / 2) << s;
      ASSERT_TRUE(e[0] > -kPi && e[0] <= kPi && e[2] > -kPi && e[2] <= kPi) << s << " " << e.transpose();
    }
  }
}

// Angles inside the principal ranges come back unchanged.
TEST(RotationsTest, RecoversPrincipalAngles) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> outer(-3.0, 3.0), middle(-1.5, 1.5);
  for (const char* s : kOrders) {
    const EulerOrder order = euler_order_from_string(s);
    for (int n = 0; n < 500; ++n) {
      const Eigen::Vector3d a(outer(rng), middle(rng), outer(rng));
      ASSERT_LT((euler_from_quat(quat_from_euler(a, order), order) - a).norm(), 1e-10) << s;
    }
  }
}

TEST(RotationsTest, DoubleCover) {
  std::mt19937 rng(3);
  for (int n = 0; n < 100; ++n) {
    const Eigen::Quaterniond q = random_quat(rng);
    const Eigen::Quaterniond minus(-q.w(), -q.x(), -q.y(), -q.z());
    EXPECT_LT(geodesic_angle(q, minus), 1e-7);
    EXPECT_EQ(geodesic_angle(q, minus), geodesic_angle(q, q));
    for (const char* s : kOrders) {
      const EulerOrder order = euler_order_from_string(s);
      EXPECT_LT((euler_from_quat(q, order) - euler_from_quat(minus, order)).norm(), 1e-12) << s;
    }
  }
}

TEST(RotationsTest, HalfTurns) {
  // 180 degrees about the first or last axis: that angle is pi, the others 0.
  const EulerOrder xyz = euler_order_from_string("XYZ");
  const Eigen::Quaterniond rx(0, 1, 0, 0), ry(0, 0, 1, 0), rz(0, 0, 0, 1);
  EXPECT_LT((euler_from_quat(rx, xyz) - Eigen::Vector3d(kPi, 0, 0)).norm(), 1e-12);
  EXPECT_LT((euler_from_quat(rz, xyz) - Eigen::Vector3d(0, 0, kPi)).norm(), 1e-12);
  // About the middle axis the middle angle cannot reach pi: Ry(pi) = Rx(pi) Ry(0) Rz(pi).
  const Eigen::Vector3d e = euler_from_quat(ry, xyz);
  EXPECT_NEAR(std::abs(e[0]), kPi, 1e-12);
  EXPECT_NEAR(e[1], 0, 1e-12);
  EXPECT_NEAR(std::abs(e[2]), kPi, 1e-12);
  EXPECT_LT(geodesic_angle(quat_from_euler(e, xyz), ry), 1e-12);
  // Angles map into (-pi, pi]: -pi comes back as +pi.
  EXPECT_NEAR(euler_from_quat(quat_from_euler({-kPi, 0, 0}, xyz), xyz)[0], kPi, 1e-12);
  EXPECT_NEAR(geodesic_angle(Eigen::Quaterniond::Identity(), rx), kPi, 1e-15);
}

TEST(RotationsTest, NearIdentity) {
  const double tiny = 1e-8;
  for (const char* s : kOrders) {
    const EulerOrder order = euler_order_from_string(s);
    for (int slot = 0; slot < 3; ++slot) {
      Eigen::Vector3d angles = Eigen::Vector3d::Zero();
      angles[slot] = tiny;
      const Eigen::Quaterniond q = quat_from_euler(angles, order);
      EXPECT_NEAR(geodesic_angle(Eigen::Quaterniond::Identity(), q), tiny, 1e-20) << s;
      EXPECT_LT((euler_from_quat(q, order) - angles).norm(), 1e-20) << s << " slot " << slot;
    }
  }
  EXPECT_EQ(geodesic_angle(Eigen::Quaterniond::Identity(), Eigen::Quaterniond::Identity()), 0.0);
}

TEST(RotationsTest, GimbalLock) {
  for (const char* s : kOrders) {
    const EulerOrder order = euler_order_from_string(s);
    for (double sign : {1.0, -1.0}) {
      const Eigen::Quaterniond q = quat_from_euler({0.3, sign * kPi / 2, 0.5}, order);
      const Eigen::Vector3d e = euler_from_quat(q, order);
      EXPECT_NEAR(e[1], sign * kPi / 2, 1e-7) << s;
      EXPECT_EQ(e[2], 0.0) << s;  // third angle zero by convention
      EXPECT_LT(geodesic_angle(q, quat_from_euler(e, order)), 1e-12) << s << " " << e.transpose();
      // Just off the singularity the decomposition is still exact.
      const Eigen::Quaterniond near = quat_from_euler({0.3, sign * (kPi / 2 - 1e-9), 0.5}, order);
      EXPECT_LT(geodesic_angle(near, quat_from_euler(euler_from_quat(near, order), order)), 1e-12) << s;
    }
  }
}

TEST(RotationsTest, NearPicksTheWrapClosestToThePreviousFrame) {
  const EulerOrder zxy = euler_order_from_string("ZXY");
  // 181 degrees about Z after a frame at 179 degrees: 181, not -179.
  const double deg = kPi / 180;
  const Eigen::Quaterniond q = quat_from_euler({181 * deg, 0, 0}, zxy);
  EXPECT_NEAR(euler_from_quat(q, zxy)[0], -179 * deg, 1e-12);
  EXPECT_NEAR(euler_from_quat_near(q, zxy, {179 * deg, 0, 0})[0], 181 * deg, 1e-12);
  // Several turns away.
  EXPECT_NEAR(euler_from_quat_near(q, zxy, {(720 + 179) * deg, 0, 0})[0], (720 + 181) * deg, 1e-10);
}

TEST(RotationsTest, NearPicksTheEquivalentTriple) {
  for (const char* s : kOrders) {
    const EulerOrder order = euler_order_from_string(s);
    const Eigen::Vector3d a(0.3, 0.2, -0.1);
    const Eigen::Quaterniond q = quat_from_euler(a, order);
    const Eigen::Vector3d other(a[0] + kPi, kPi - a[1], a[2] + kPi);
    EXPECT_LT(geodesic_angle(q, quat_from_euler(other, order)), 1e-12) << s;  // same rotation
    EXPECT_LT((euler_from_quat_near(q, order, other + Eigen::Vector3d(0.01, -0.02, 0.01)) - other).norm(), 1e-10) << s;
    EXPECT_LT((euler_from_quat_near(q, order, a + Eigen::Vector3d(0.01, -0.02, 0.01)) - a).norm(), 1e-10) << s;
  }
}

// At the lock (middle +90 degrees) only a + c (cyclic orders XYZ, YZX, ZXY) or
// a - c (the others) is determined: here 0.8 or -0.2.
TEST(RotationsTest, NearKeepsThePreviousThirdAngleInGimbalLock) {
  for (const char* s : kOrders) {
    const EulerOrder order = euler_order_from_string(s);
    const bool cyclic = std::string(s) == "XYZ" || std::string(s) == "YZX" || std::string(s) == "ZXY";
    const Eigen::Quaterniond q = quat_from_euler({0.3, kPi / 2, 0.5}, order);
    const Eigen::Vector3d e = euler_from_quat_near(q, order, {0.31, 1.5, 0.49});
    EXPECT_NEAR(e[2], 0.49, 1e-12) << s;
    EXPECT_NEAR(e[0], cyclic ? 0.8 - 0.49 : -0.2 + 0.49, 1e-9) << s;
    EXPECT_LT(geodesic_angle(q, quat_from_euler(e, order)), 1e-12) << s;
  }
}

// A curve whose middle angle goes beyond 90 degrees and whose outer angles wind
// several turns: euler_from_quat folds it, euler_from_quat_near follows it.
TEST(RotationsTest, NearFollowsContinuousCurves) {
  for (const char* s : kOrders) {
    const EulerOrder order = euler_order_from_string(s);
    Eigen::Vector3d previous = Eigen::Vector3d::Zero();
    for (int f = 0; f <= 400; ++f) {
      const double t = f * 0.025;
      const Eigen::Vector3d truth(2.0 * t, 1.3 + 0.4 * std::sin(3 * t), -1.5 * t);
      const Eigen::Quaterniond q = quat_from_euler(truth, order);
      const Eigen::Vector3d e = f == 0 ? euler_from_quat(q, order) : euler_from_quat_near(q, order, previous);
      ASSERT_LT((e - truth).norm(), 1e-8) << s << " frame " << f << ": " << e.transpose();
      previous = e;
    }
  }
}

TEST(RotationsTest, SixD) {
  std::mt19937 rng(5);
  for (int n = 0; n < 100; ++n) {
    const Eigen::Matrix3d m = random_quat(rng).toRotationMatrix();
    const Vector6d d = sixd_from_matrix(m);
    EXPECT_EQ(d[1], m(1, 0));
    EXPECT_EQ(d[3], m(0, 1));
    EXPECT_LT((matrix_from_sixd(d) - m).norm(), 1e-14);
    // Scaling and shearing the halves does not change the result.
    Vector6d skewed;
    skewed << 3.0 * d.head<3>(), 0.5 * d.tail<3>() + 0.7 * d.head<3>();
    EXPECT_LT((matrix_from_sixd(skewed) - m).norm(), 1e-12);
  }
  // Hand case: x = (2,0,0) -> (1,0,0); y = (1,3,0) minus its x part -> (0,1,0); z = x cross y.
  Vector6d hand;
  hand << 2, 0, 0, 1, 3, 0;
  EXPECT_LT((matrix_from_sixd(hand) - Eigen::Matrix3d::Identity()).norm(), 1e-15);
  // Degenerate inputs still give a rotation.
  for (const Vector6d& bad : {Vector6d(Vector6d::Zero()), Vector6d((Vector6d() << 1, 2, 3, 2, 4, 6).finished())}) {
    const Eigen::Matrix3d r = matrix_from_sixd(bad);
    EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  }
}

TEST(RotationsTest, Slerp) {
  const Eigen::Quaterniond a = Eigen::Quaterniond::Identity();
  const Eigen::Quaterniond b(Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()));
  const Eigen::Quaterniond half(Eigen::AngleAxisd(kPi / 4, Eigen::Vector3d::UnitZ()));
  EXPECT_LT(geodesic_angle(slerp(a, b, 0.0), a), 1e-15);
  EXPECT_LT(geodesic_angle(slerp(a, b, 1.0), b), 1e-15);
  EXPECT_LT(geodesic_angle(slerp(a, b, 0.5), half), 1e-15);
  // Shortest path: -b is the same rotation and gives the same midpoint.
  const Eigen::Quaterniond minus_b(-b.w(), -b.x(), -b.y(), -b.z());
  EXPECT_LT(geodesic_angle(slerp(a, minus_b, 0.5), half), 1e-15);
  // Constant angular speed: a quarter of the way is a quarter of the angle.
  EXPECT_NEAR(geodesic_angle(a, slerp(a, b, 0.25)), kPi / 8, 1e-14);
  // Nearly equal inputs take the linear fallback and stay unit.
  const Eigen::Quaterniond c(Eigen::AngleAxisd(1e-9, Eigen::Vector3d::UnitX()));
  const Eigen::Quaterniond mid = slerp(a, c, 0.5);
  EXPECT_NEAR(mid.norm(), 1.0, 1e-15);
  EXPECT_NEAR(geodesic_angle(a, mid), 0.5e-9, 1e-15);
}

TEST(RotationsTest, GeodesicAngle) {
  const Eigen::Quaterniond a(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()));
  const Eigen::Quaterniond b(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX()));
  EXPECT_NEAR(geodesic_angle(a, b), 0.3, 1e-15);
  EXPECT_NEAR(geodesic_angle(b, a), 0.3, 1e-15);
  // 350 degrees one way is 10 degrees the other.
  const Eigen::Quaterniond c(Eigen::AngleAxisd(350 * kPi / 180, Eigen::Vector3d::UnitY()));
  EXPECT_NEAR(geodesic_angle(Eigen::Quaterniond::Identity(), c), 10 * kPi / 180, 1e-14);
}

}  // namespace
}  // namespace mf
