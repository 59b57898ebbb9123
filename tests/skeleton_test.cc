// Tests of Skeleton, Motion and double-precision forward kinematics
// (prior/motion/skeleton.h, motion.h).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "prior/motion/errors.h"
#include "prior/motion/motion.h"
#include "tests/test_util.h"

namespace mf {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Quaterniond about(double angle, const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis));
}

// root -> a -> b, a chain along the axes.
Skeleton chain() {
  Skeleton s;
  s.names = {"root", "a", "b"};
  s.parents = {-1, 0, 1};
  s.offsets = {{5, 5, 5}, {0, 0, 1}, {0, 1, 0}};
  return s;
}

TEST(SkeletonTest, FindAndChildren) {
  const Skeleton s = test::small_skeleton();
  EXPECT_EQ(s.find("Hips"), 0);
  EXPECT_EQ(s.find("Foot_R"), 6);
  EXPECT_EQ(s.find("Nope"), -1);
  const auto children = s.children();
  ASSERT_EQ(children.size(), 7u);
  EXPECT_EQ(children[0], (std::vector<int>{1, 3, 5}));
  EXPECT_EQ(children[1], (std::vector<int>{2}));
  EXPECT_TRUE(children[2].empty());
  EXPECT_EQ(children[5], (std::vector<int>{6}));
}

TEST(SkeletonTest, ValidateAcceptsAGoodSkeleton) {
  EXPECT_NO_THROW(test::small_skeleton().validate());
  EXPECT_NO_THROW(chain().validate());
}

TEST(SkeletonTest, ValidateRejectsBadSkeletons) {
  EXPECT_THROW(Skeleton().validate(), InputError);  // no joints
  auto expect_invalid = [](void (*edit)(Skeleton&), const char* what) {
    Skeleton s = test::small_skeleton();
    edit(s);
    EXPECT_THROW(s.validate(), InputError) << what;
  };
  expect_invalid([](Skeleton& s) { s.parents.pop_back(); }, "sizes");
  expect_invalid([](Skeleton& s) { s.offsets.push_back({0, 0, 0}); }, "sizes");
  expect_invalid([](Skeleton& s) { s.parents[0] = 1; }, "joint 0 not a root");
  expect_invalid([](Skeleton& s) { s.parents[3] = -1; }, "second root");
  expect_invalid([](Skeleton& s) { s.parents[2] = 4; }, "parent after child");
  expect_invalid([](Skeleton& s) { s.parents[2] = 2; }, "own parent");
  expect_invalid([](Skeleton& s) { s.parents[2] = 99; }, "out of range");
  expect_invalid([](Skeleton& s) { s.names[4] = "Spine"; }, "duplicate name");
  expect_invalid([](Skeleton& s) { s.names[4] = ""; }, "empty name");
  expect_invalid([](Skeleton& s) { s.offsets[2].y() = std::numeric_limits<double>::quiet_NaN(); }, "NaN offset");
  expect_invalid([](Skeleton& s) { s.offsets[2].x() = std::numeric_limits<double>::infinity(); }, "inf offset");
}

TEST(SkeletonTest, SameAs) {
  const Skeleton a = test::small_skeleton();
  Skeleton b = a;
  EXPECT_TRUE(a.same_as(b));
  b.offsets[3].x() += 0.5e-4;
  EXPECT_TRUE(a.same_as(b));
  EXPECT_FALSE(a.same_as(b, 1e-5));
  b.offsets[3].x() += 1e-3;
  EXPECT_FALSE(a.same_as(b));
  b = a;
  b.names[2] = "Skull";
  EXPECT_FALSE(a.same_as(b));
  b = a;
  b.parents[6] = 3;
  EXPECT_FALSE(a.same_as(b));
  b = a;
  b.offsets[1].y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(a.same_as(b));
  EXPECT_FALSE(a.same_as(chain()));
  // The root's offset (its rest position) is not part of the rig.
  b = a;
  b.offsets[0] = Eigen::Vector3d(0.3, 0.9, -4.5);
  EXPECT_TRUE(a.same_as(b, 0.0));
}

TEST(MotionTest, Identity) {
  const Motion m = Motion::identity(test::small_skeleton(), 4, 25.0);
  EXPECT_EQ(m.num_frames(), 4);
  EXPECT_EQ(m.num_joints(), 7);
  EXPECT_EQ(m.rotations.size(), 28u);
  EXPECT_DOUBLE_EQ(m.frame_time(), 0.04);
  for (const auto& q : m.rotations) EXPECT_EQ(q.coeffs(), Eigen::Quaterniond::Identity().coeffs());
  for (const auto& p : m.root_positions) EXPECT_EQ(p, Eigen::Vector3d::Zero());
  EXPECT_NO_THROW(m.validate());
  EXPECT_EQ(Motion::identity(test::small_skeleton(), 0, 30.0).num_frames(), 0);
  EXPECT_THROW(Motion::identity(test::small_skeleton(), -1, 30.0), InputError);
}

TEST(MotionTest, Slice) {
  const Motion m = test::random_motion(test::small_skeleton(), 10, 30.0, 1);
  const Motion s = m.slice(3, 7);
  ASSERT_EQ(s.num_frames(), 4);
  EXPECT_EQ(s.fps, 30.0);
  EXPECT_TRUE(s.skeleton.same_as(m.skeleton, 0.0));
  for (int f = 0; f < 4; ++f) {
    EXPECT_EQ(s.root_positions[f], m.root_positions[f + 3]);
    for (int j = 0; j < 7; ++j) EXPECT_EQ(s.rotation(f, j).coeffs(), m.rotation(f + 3, j).coeffs());
  }
  EXPECT_EQ(m.slice(5, 5).num_frames(), 0);
  EXPECT_EQ(m.slice(0, 10).num_frames(), 10);
  EXPECT_THROW(m.slice(-1, 3), InputError);
  EXPECT_THROW(m.slice(4, 3), InputError);
  EXPECT_THROW(m.slice(0, 11), InputError);
}

TEST(MotionTest, ValidateRejectsBadMotions) {
  const Motion good = test::random_motion(test::small_skeleton(), 5, 30.0, 2);
  EXPECT_NO_THROW(good.validate());
  Motion m = good;
  m.rotations.pop_back();
  EXPECT_THROW(m.validate(), InputError);
  m = good;
  m.root_positions.push_back({0, 0, 0});
  EXPECT_THROW(m.validate(), InputError);
  m = good;
  m.fps = 0;
  EXPECT_THROW(m.validate(), InputError);
  m.fps = std::numeric_limits<double>::infinity();
  EXPECT_THROW(m.validate(), InputError);
  m = good;
  m.root_positions[2].z() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(m.validate(), InputError);
  m = good;
  m.rotation(3, 4).x() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(m.validate(), InputError);
  m = good;
  m.rotation(3, 4).coeffs().setZero();
  EXPECT_THROW(m.validate(), InputError);
  m = good;
  m.skeleton.parents[1] = 5;
  EXPECT_THROW(m.validate(), InputError);
}

TEST(ForwardKinematicsTest, RestPoseAddsOffsets) {
  Motion m = Motion::identity(test::small_skeleton(), 2, 30.0);
  m.root_positions[1] = {1, 0.9, 2};
  const GlobalPose p = forward_kinematics(m);
  EXPECT_EQ(p.frames, 2);
  EXPECT_EQ(p.joints, 7);
  EXPECT_LT((p.position(0, 0) - Eigen::Vector3d(0, 0, 0)).norm(), 1e-15);  // root offset unused
  EXPECT_LT((p.position(0, 2) - Eigen::Vector3d(0, 0.6, 0)).norm(), 1e-15);
  EXPECT_LT((p.position(0, 4) - Eigen::Vector3d(0.1, -0.85, 0)).norm(), 1e-15);
  EXPECT_LT((p.position(1, 6) - Eigen::Vector3d(0.9, 0.05, 2)).norm(), 1e-15);
}

// Hand-computed: root at (1,2,3) turned 90 degrees about Y (z -> x); a's offset
// (0,0,1) lands at root + (1,0,0). a turns 90 about X; b's offset (0,1,0) goes
// through Rx: (0,0,1), then Ry: (1,0,0).
TEST(ForwardKinematicsTest, HandComputedChain) {
  Motion m = Motion::identity(chain(), 1, 30.0);
  m.root_positions[0] = {1, 2, 3};
  m.rotation(0, 0) = about(kPi / 2, Eigen::Vector3d::UnitY());
  m.rotation(0, 1) = about(kPi / 2, Eigen::Vector3d::UnitX());
  const GlobalPose p = forward_kinematics(m);
  EXPECT_LT((p.position(0, 0) - Eigen::Vector3d(1, 2, 3)).norm(), 1e-15);
  EXPECT_LT((p.position(0, 1) - Eigen::Vector3d(2, 2, 3)).norm(), 1e-15);
  EXPECT_LT((p.position(0, 2) - Eigen::Vector3d(3, 2, 3)).norm(), 1e-15);
  const Eigen::Quaterniond expected =
      about(kPi / 2, Eigen::Vector3d::UnitY()) * about(kPi / 2, Eigen::Vector3d::UnitX());
  EXPECT_NEAR(std::abs(p.rotation(0, 2).coeffs().dot(expected.coeffs())), 1.0, 1e-15);
  EXPECT_NEAR(std::abs(p.rotation(0, 0).coeffs().dot(m.rotation(0, 0).coeffs())), 1.0, 1e-15);
}

// Unnormalised local rotations are normalised before use.
TEST(ForwardKinematicsTest, NormalisesRotations) {
  Motion m = Motion::identity(chain(), 1, 30.0);
  m.rotation(0, 0) = Eigen::Quaterniond(about(kPi / 2, Eigen::Vector3d::UnitY()).coeffs() * 3.0);
  const GlobalPose p = forward_kinematics(m);
  EXPECT_LT((p.position(0, 1) - Eigen::Vector3d(1, 0, 0)).norm(), 1e-15);
  EXPECT_NEAR(p.rotation(0, 0).norm(), 1.0, 1e-15);
}

}  // namespace
}  // namespace mf
