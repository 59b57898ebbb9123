// The trainers' data loading: left/right mirrors, frame-noise copies and clips
// played at other speeds are appended to the training split only, with the
// checks on bad options.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "prior/motion/errors.h"
#include "prior/motion/interpolation.h"
#include "prior/motion/motion_bvh.h"
#include "prior/motion/rotations.h"
#include "tests/test_util.h"
#include "training/augmentation.h"
#include "training/trainer_util.h"

namespace mf {
namespace {

// A clip played 1.25 times as fast: frame i is the clip at frame position
// 1.25 i (exact where that is a whole frame, Catmull-Rom between), at the same
// rate, and it covers the whole clip; half speed doubles the frames.
TEST(TrainingData, PlayedAtSpeedSamplesTheClipAtScaledTimes) {
  const Motion m = test::random_motion(test::small_skeleton(), 41, 30.0, 7);
  const Motion fast = played_at_speed(m, 1.25);
  EXPECT_EQ(fast.num_frames(), 33);  // positions 0, 1.25, ..., 40
  EXPECT_DOUBLE_EQ(fast.fps, 30.0);
  for (int i = 0; i < fast.num_frames(); i += 4) {  // i = 4k lands on frame 5k
    EXPECT_EQ((fast.root_positions[i] - m.root_positions[i * 5 / 4]).norm(), 0.0) << i;
    for (int j = 0; j < m.num_joints(); ++j)
      EXPECT_LT(geodesic_angle(fast.rotation(i, j), m.rotation(i * 5 / 4, j)), 1e-12) << i << " " << j;
  }
  // Between frames: near the two neighbours' blend (a smooth clip's spline stays close to it).
  Motion smooth = m;
  for (int f = 0; f < m.num_frames(); ++f) smooth.root_positions[f] = Eigen::Vector3d(0.1 * f, 1.0, 0.02 * f * f);
  const Motion fast_smooth = played_at_speed(smooth, 1.25);
  EXPECT_NEAR(fast_smooth.root_positions[1].x(), 0.125, 1e-9);
  EXPECT_NEAR(fast_smooth.root_positions[1].z(), 0.02 * 1.25 * 1.25, 1e-3);
  EXPECT_EQ(played_at_speed(m, 0.5).num_frames(), 81);
}

TEST(TrainingData, AugmentationAddsToTheTrainingSplitOnly) {
  const std::string dir = test::scratch_dir("training_data_speeds");
  // The training rig (symmetric, so it can be mirrored): a few slices of the sample walk.
  const Motion walk = read_motion(std::string(MF_SOURCE_DIR) + "/samples/walk_keyframes.bvh");
  for (int i = 0; i < 12; ++i)
    write_motion(dir + "/clip" + std::to_string(i) + ".bvh", walk.slice(i, 40 + i), default_bvh_layout(walk.skeleton));
  const Dataset plain = training::load_training_data(dir, dir + "/cache", 0, 0.0, {}, false);
  training::Augmentation a;
  a.mirror = true;
  a.speeds = {0.8, 1.25};
  const Dataset more = training::load_training_data(dir, dir + "/cache", 0, 0.0, a, false);
  const size_t n = plain.train.size();
  ASSERT_GT(n, 0u);
  ASSERT_EQ(more.train.size(), 6 * n);  // originals, mirrors, then both at each speed
  EXPECT_EQ(more.validation.size(), plain.validation.size());
  EXPECT_EQ(more.train[n].name, plain.train[0].name + "#mirror");
  EXPECT_EQ(more.train[2 * n].name, plain.train[0].name + "@0.8x");
  EXPECT_EQ(more.train[5 * n].name, plain.train[0].name + "#mirror@1.25x");
  EXPECT_EQ(more.train[2 * n].motion.num_frames(), played_at_speed(plain.train[0].motion, 0.8).num_frames());
  a.frame_noise_degrees = 5.0;
  const Dataset noisy = training::load_training_data(dir, dir + "/cache", 0, 0.0, a, false);
  ASSERT_EQ(noisy.train.size(), 12 * n);  // originals, mirrors, their noisy copies, then all at each speed
  EXPECT_EQ(noisy.train[3 * n].name, plain.train[0].name + "#mirror#noise");
  EXPECT_EQ(noisy.train[11 * n].name, plain.train[0].name + "#mirror#noise@1.25x");
  EXPECT_EQ(noisy.validation.size(), plain.validation.size());
  for (double bad : {1.0, 0.3, 2.5, std::nan("")}) {
    training::Augmentation b;
    b.speeds = {bad};
    EXPECT_THROW(training::load_training_data(dir, dir + "/cache", 0, 0.0, b, false), InputError) << bad;
  }
  for (double bad : {-1.0, 46.0, std::nan("")}) {
    training::Augmentation b;
    b.frame_noise_degrees = bad;
    EXPECT_THROW(training::load_training_data(dir, dir + "/cache", 0, 0.0, b, false), InputError) << bad;
  }
}

// Frame noise: each joint's world rotation turns by one constant rotation in
// its own frame, G_j E_j, of at most the bound (a different one per joint,
// the root's none), the same for the same seed, and the body is moved so that
// its lowest point stays on the floor on average.
TEST(TrainingData, FrameNoiseTurnsEachJointFrameByAConstantBoundedRotation) {
  const Motion m = read_motion(std::string(MF_SOURCE_DIR) + "/samples/walk_keyframes.bvh");
  const Motion noisy = training::with_frame_noise(m, 10.0, 42);
  ASSERT_EQ(noisy.num_frames(), m.num_frames());
  const GlobalPose g = forward_kinematics(m), h = forward_kinematics(noisy);
  double largest = 0.0;
  for (int j = 0; j < m.num_joints(); ++j) {
    const Eigen::Quaterniond turn0 = g.rotation(0, j).conjugate() * h.rotation(0, j);
    const double angle = geodesic_angle(turn0, Eigen::Quaterniond::Identity());
    largest = std::max(largest, angle);
    EXPECT_LE(angle, 10.0 * M_PI / 180.0 + 1e-9) << j;
    if (j == 0) {
      EXPECT_LT(angle, 1e-12);
    }
    for (int f = 0; f < m.num_frames(); f += 7) {
      const Eigen::Quaterniond turn = g.rotation(f, j).conjugate() * h.rotation(f, j);
      EXPECT_LT(geodesic_angle(turn, turn0), 1e-9) << f << " " << j;  // constant over the clip
    }
  }
  EXPECT_GT(largest, 2.0 * M_PI / 180.0);  // the joints did turn
  for (int f = 0; f < m.num_frames(); ++f) {  // the root path keeps its shape: one constant vertical shift
    EXPECT_NEAR(noisy.root_positions[f].x(), m.root_positions[f].x(), 1e-12);
    EXPECT_NEAR(noisy.root_positions[f].y() - m.root_positions[f].y(),
                noisy.root_positions[0].y() - m.root_positions[0].y(), 1e-12);
  }
  auto mean_lowest = [](const Motion& x) {
    const GlobalPose p = forward_kinematics(x);
    double sum = 0.0;
    for (int f = 0; f < p.frames; ++f) {
      double low = 1e9;
      for (int j = 0; j < p.joints; ++j) low = std::min(low, p.position(f, j).y());
      sum += low;
    }
    return sum / p.frames;
  };
  EXPECT_NEAR(mean_lowest(noisy), mean_lowest(m), 1e-9);
  const Motion again = training::with_frame_noise(m, 10.0, 42), other = training::with_frame_noise(m, 10.0, 43);
  auto same = [](const Motion& x, const Motion& y) {
    for (size_t i = 0; i < x.rotations.size(); ++i)
      if (x.rotations[i].coeffs() != y.rotations[i].coeffs()) return false;
    return true;
  };
  EXPECT_TRUE(same(again, noisy));
  EXPECT_FALSE(same(other, noisy));
}

}  // namespace
}  // namespace mf
