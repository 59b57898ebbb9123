// Foot locking after a solve (tasks/fixups/foot_locking.h) on a one-legged rig with a
// toe: a toe in contact is held whether its heel is planted (the foot turns
// about the ankle) or lifted (the leg carries the foot, which keeps its
// orientation), frames a key protects are not touched, and the ramp into a
// contact keeps the swing smooth.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <vector>

#include "prior/model/representation.h"
#include "prior/motion/motion.h"
#include "tasks/constraints/motion_constraints.h"
#include "tasks/fixups/foot_locking.h"

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

// A foot that swings 3 cm a frame until frame 10, then slides 1 cm a frame over
// its contact (frames 10..19): the lock point, the contact's mean, is 4.5 cm
// ahead of the foot's first contact frame and further ahead of its swing. The
// ramp pulls the swinging foot toward it a little at first and more near the
// contact, so no frame moves the foot much more than its own step (the linear
// 3-frame ramp moved it 6.4 cm, over twice its step, on the ramp's first frame).
Motion swing_into_contact() {
  Motion m = turning_foot(/*walk=*/false);
  for (int f = 0; f < kFrames; ++f) {
    m.rotation(f, kFoot) = m.rotation(0, kFoot);
    m.root_positions[f].z() = f < 10 ? 0.03 * (f - 10) : 0.01 * (f - 10);
  }
  return m;
}

std::vector<float> foot_down_from_frame_10() {
  std::vector<float> c;
  for (int f = 0; f < kFrames; ++f) c.insert(c.end(), {f < 10 ? 0.0f : 1.0f, 0.0f});
  return c;
}

TEST(FootLocking, TheRampIntoAContactKeepsTheSwingSmooth) {
  const Motion m = swing_into_contact();
  Motion out = m;
  lock_feet(leg_rig(m.skeleton), MotionConstraints{}, foot_down_from_frame_10(), kFootLockRamp, &out);
  EXPECT_LT(horizontal_spread(out, kFoot, 10, kFrames - 1), 0.002);
  const GlobalPose before = forward_kinematics(m), after = forward_kinematics(out);
  for (int f = 1; f <= 10; ++f) {
    const Eigen::Vector3d step = after.position(f, kFoot) - after.position(f - 1, kFoot);
    EXPECT_LT(std::hypot(step.x(), step.z()), 1.6 * 0.03) << "frame " << f;
  }
  for (int f = 0; f < 10 - kFootLockRamp; ++f)  // before the ramp: untouched
    EXPECT_LT((after.position(f, kFoot) - before.position(f, kFoot)).norm(), 1e-9) << "frame " << f;
}

// The same swing with a full-pose key at frame 8, inside the ramp: the ramp
// starts at the key, so frame 9, the one free frame between the key and the
// contact, moves a quarter of the way to the lock point (7.5 cm away), not
// the 69 % of a ramp that ignored the key.
TEST(FootLocking, AKeyInsideARampStartsTheRampThere) {
  const Motion m = swing_into_contact();
  Motion out = m;
  lock_feet(leg_rig(m.skeleton), MotionConstraints::full_pose({8}), foot_down_from_frame_10(), kFootLockRamp, &out);
  const GlobalPose before = forward_kinematics(m), after = forward_kinematics(out);
  for (int j = 0; j < m.num_joints(); ++j) EXPECT_EQ(out.rotation(8, j).coeffs(), m.rotation(8, j).coeffs());
  const Eigen::Vector3d moved = after.position(9, kFoot) - before.position(9, kFoot);
  EXPECT_NEAR(std::hypot(moved.x(), moved.z()), 0.25 * 0.075, 2e-3);
  EXPECT_LT(horizontal_spread(out, kFoot, 10, kFrames - 1), 0.002);
}

// A contact pin on a nearly straight leg whose hips walk 3 cm a frame, with a
// full-pose key at frame 12 inside it: the pinned point (where the key puts
// the foot) is out of the leg's reach on the contact's other frames, so the IK
// alone would stop short and the foot slide. The root moves toward it by the
// shortfall on the frames it is free, and keeps its value on the keyed frame.
TEST(FootLocking, AContactPinOutOfReachMovesTheFreeRootByTheShortfall) {
  Motion m = Motion::identity(leg_with_toe(), kFrames, 30.0);
  for (int f = 0; f < kFrames; ++f) m.root_positions[f] = Eigen::Vector3d(0, 0.85, 0.03 * f);
  MotionConstraints c = MotionConstraints::full_pose({12});
  c.contacts.push_back(ContactPin{kFoot, 4, 15});
  Motion out = m;
  const std::vector<std::string> warnings = pin_contacts(c, kDefaultContactRamp, &out);
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  const GlobalPose pose = forward_kinematics(out);
  for (int f = 4; f <= 15; ++f) {
    if (f == 12) continue;  // the key keeps the leg and the root there
    EXPECT_LT((pose.position(f, kFoot) - pose.position(4, kFoot)).norm(), 1e-3) << "frame " << f;
  }
  EXPECT_EQ(out.root_positions[12], m.root_positions[12]);
  for (int j = 0; j < m.num_joints(); ++j) EXPECT_EQ(out.rotation(12, j).coeffs(), m.rotation(12, j).coeffs());
  double moved = 0.0, jump = 0.0;
  for (int f = 0; f < kFrames; ++f) {
    moved = std::max(moved, (out.root_positions[f] - m.root_positions[f]).norm());
    if (f > 0) jump = std::max(jump, (out.root_positions[f] - out.root_positions[f - 1]).norm());
  }
  EXPECT_GT(moved, 0.02);  // frame 4 is 3.3 cm out of reach: sqrt(0.84^2 + 0.24^2) - 0.84
  EXPECT_LT(moved, 0.04);
  EXPECT_LT(jump, 0.04);  // a root path of 3 cm a frame stays continuous
  // Without the root's help the same pin slides (the test's premise).
  Motion ik_only = m;
  MotionConstraints all_keyed = c;
  for (int f = 0; f < kFrames; ++f) {
    PoseKey root_only;
    root_only.frame = f;
    root_only.rotations = false;
    if (f != 12) all_keyed.keys.push_back(root_only);
  }
  pin_contacts(all_keyed, kDefaultContactRamp, &ik_only);
  const GlobalPose stuck = forward_kinematics(ik_only);
  EXPECT_GT((stuck.position(15, kFoot) - stuck.position(5, kFoot)).norm(), 5e-3);
}

// Two legs whose contacts overlap on frames 8..11 while the hips walk 3 cm a
// frame: both pinned points are out of reach on some of those frames. Each
// root move carries the whole body, so both happen before either foot is
// held; otherwise the right leg's move would shift the left foot, already held.
TEST(FootLocking, TwoContactPinsOutOfReachOnTheSameFramesBothHold) {
  Skeleton s;
  s.names = {"Hips", "UpperLeg_L", "LowerLeg_L", "Foot_L", "UpperLeg_R", "LowerLeg_R", "Foot_R"};
  s.parents = {-1, 0, 1, 2, 0, 4, 5};
  s.offsets = {{0, 0, 0}, {0.1, -0.05, 0}, {0, -0.42, 0.02}, {0, -0.42, -0.02},
               {-0.1, -0.05, 0}, {0, -0.42, 0.02}, {0, -0.42, -0.02}};
  Motion m = Motion::identity(s, kFrames, 30.0);
  for (int f = 0; f < kFrames; ++f) m.root_positions[f] = Eigen::Vector3d(0, 0.85, 0.03 * f);
  MotionConstraints c;
  c.contacts.push_back(ContactPin{3, 0, 11});
  c.contacts.push_back(ContactPin{6, 8, 19});
  Motion out = m;
  const std::vector<std::string> warnings = pin_contacts(c, kDefaultContactRamp, &out);
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  const GlobalPose pose = forward_kinematics(out);
  for (const ContactPin& p : c.contacts) {
    for (int f = p.first + 1; f <= p.last; ++f)
      EXPECT_LT((pose.position(f, p.joint) - pose.position(p.first, p.joint)).norm(), 1e-3)
          << s.names[p.joint] << " frame " << f;
  }
  double moved = 0.0;
  for (int f = 0; f < kFrames; ++f) moved = std::max(moved, (out.root_positions[f] - m.root_positions[f]).norm());
  EXPECT_GT(moved, 0.01);  // the premise: the root had to move
}

}  // namespace
}  // namespace mf
