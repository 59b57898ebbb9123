// Foot locking after a solve (tasks/foot_locking.h) on a one-legged rig with a
// toe: a toe in contact is held whether its heel is planted (the foot turns
// about the ankle) or lifted (the leg carries the foot, which keeps its
// orientation), and frames a key protects are not touched.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "prior/model/representation.h"
#include "prior/motion/motion.h"
#include "tasks/foot_locking.h"
#include "tasks/motion_constraints.h"

namespace mf {
namespace {

constexpr int kFoot = 3, kToe = 4, kFrames = 20;

Skeleton leg_with_toe() {
  Skeleton s;
  s.names = {"Hips", "UpperLeg_L", "LowerLeg_L", "Foot_L", "Toes_L"};
  s.parents = {-1, 0, 1, 2, 3};
  s.offsets = {{0, 0, 0}, {0.1, -0.05, 0}, {0, -0.42, 0.02}, {0, -0.42, -0.02}, {0, -0.08, 0.14}};
  return s;
}

RigInfo leg_rig(const Skeleton& s) {
  RigInfo rig;
  rig.skeleton = s;
  rig.foot_joints = {kFoot, kToe};
  rig.foot_heights = {0.0, 0.0};
  rig.foot_thresholds = {10.0, 10.0};  // every height counts as low
  return rig;
}

// A leg standing with a bent knee whose foot turns about the vertical by up
// to 24 degrees over the clip; with `walk`, the hips also move 1 cm per frame
// along +Z, carrying the whole leg.
Motion turning_foot(bool walk) {
  Motion m = Motion::identity(leg_with_toe(), kFrames, 30.0);
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY();
  for (int f = 0; f < kFrames; ++f) {
    m.root_positions[f] = Eigen::Vector3d(0, 0.85, walk ? 0.01 * f : 0.0);
    m.rotation(f, 1) = Eigen::Quaterniond(Eigen::AngleAxisd(-0.44, x));
    m.rotation(f, 2) = Eigen::Quaterniond(Eigen::AngleAxisd(0.88, x));
    // The foot's global rotation: the turn about the vertical only.
    m.rotation(f, kFoot) = Eigen::Quaterniond(Eigen::AngleAxisd(-0.44, x) * Eigen::AngleAxisd(0.021 * f, y));
  }
  return m;
}

// Largest horizontal distance of `joint` over the frames from its mean there.
double horizontal_spread(const Motion& m, int joint, int first, int last) {
  const GlobalPose pose = forward_kinematics(m);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int f = first; f <= last; ++f) mean += pose.position(f, joint);
  mean /= (last - first + 1);
  double spread = 0.0;
  for (int f = first; f <= last; ++f) {
    const Eigen::Vector3d d = pose.position(f, joint) - mean;
    spread = std::max(spread, std::hypot(d.x(), d.z()));
  }
  return spread;
}

std::vector<float> contacts(float foot, float toe) {
  std::vector<float> c;
  for (int f = 0; f < kFrames; ++f) c.insert(c.end(), {foot, toe});
  return c;
}

TEST(FootLocking, ToeOfAPlantedFootIsHeldByTurningTheFoot) {
  Motion m = turning_foot(/*walk=*/false);
  ASSERT_GT(horizontal_spread(m, kToe, 0, kFrames - 1), 0.02);  // the toe sweeps a few centimetres
  Motion out = m;
  lock_feet(leg_rig(m.skeleton), MotionConstraints{}, contacts(1.0f, 1.0f), kFootLockRamp, &out);
  EXPECT_LT(horizontal_spread(out, kToe, 0, kFrames - 1), 0.002);
  // The heel stays planted where it was.
  const GlobalPose before = forward_kinematics(m), after = forward_kinematics(out);
  for (int f = 0; f < kFrames; ++f)
    EXPECT_LT((after.position(f, kFoot) - before.position(f, kFoot)).norm(), 1e-3) << "frame " << f;
}

TEST(FootLocking, ToeOfALiftedHeelIsHeldByMovingTheLeg) {
  Motion m = turning_foot(/*walk=*/true);
  ASSERT_GT(horizontal_spread(m, kToe, 0, kFrames - 1), 0.08);
  Motion out = m;
  lock_feet(leg_rig(m.skeleton), MotionConstraints{}, contacts(0.0f, 1.0f), kFootLockRamp, &out);
  EXPECT_LT(horizontal_spread(out, kToe, 0, kFrames - 1), 0.002);
  // The foot keeps its global orientation; the hips do not move.
  const GlobalPose before = forward_kinematics(m), after = forward_kinematics(out);
  for (int f = 0; f < kFrames; ++f) {
    EXPECT_LT(after.rotation(f, kFoot).angularDistance(before.rotation(f, kFoot)), 1e-6) << "frame " << f;
    EXPECT_EQ(out.root_positions[f], m.root_positions[f]);
  }
}

TEST(FootLocking, ToesOutOfContactAndKeyedFramesAreLeftAlone) {
  const Motion m = turning_foot(/*walk=*/true);
  Motion out = m;
  lock_feet(leg_rig(m.skeleton), MotionConstraints{}, contacts(0.0f, 0.0f), kFootLockRamp, &out);
  for (int f = 0; f < kFrames; ++f)
    for (int j = 0; j < m.num_joints(); ++j) EXPECT_EQ(out.rotation(f, j).coeffs(), m.rotation(f, j).coeffs());

  // A full-pose key at frame 10: that frame keeps its values, the others are held.
  out = m;
  lock_feet(leg_rig(m.skeleton), MotionConstraints::full_pose({10}), contacts(0.0f, 1.0f), kFootLockRamp, &out);
  for (int j = 0; j < m.num_joints(); ++j) EXPECT_EQ(out.rotation(10, j).coeffs(), m.rotation(10, j).coeffs());
  EXPECT_LT(horizontal_spread(out, kToe, 0, 9), 0.002);
}

}  // namespace
}  // namespace mf
