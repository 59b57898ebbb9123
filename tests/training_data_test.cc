// The trainers' data loading: left/right mirrors and clips played at other
// speeds are appended to the training split only, with the checks on bad speeds.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "prior/motion/errors.h"
#include "prior/motion/motion_bvh.h"
#include "prior/motion/rotations.h"
#include "tests/test_util.h"
#include "training/trainer_util.h"

namespace mf {
namespace {

// A clip played 1.25 times as fast: frame i is the clip at frame position
// 1.25 i (exact where that is a whole frame, Catmull-Rom between), at the same
// rate, and it covers the whole clip; half speed doubles the frames.
TEST(TrainingData, PlayedAtSpeedSamplesTheClipAtScaledTimes) {
  const Motion m = test::random_motion(test::small_skeleton(), 41, 30.0, 7);
  const Motion fast = training::played_at_speed(m, 1.25);
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
  const Motion fast_smooth = training::played_at_speed(smooth, 1.25);
  EXPECT_NEAR(fast_smooth.root_positions[1].x(), 0.125, 1e-9);
  EXPECT_NEAR(fast_smooth.root_positions[1].z(), 0.02 * 1.25 * 1.25, 1e-3);
  EXPECT_EQ(training::played_at_speed(m, 0.5).num_frames(), 81);
}

TEST(TrainingData, SpeedsAndMirrorsAugmentOnlyTheTrainingSplit) {
  const std::string dir = test::scratch_dir("training_data_speeds");
  // The training rig (symmetric, so it can be mirrored): a few slices of the sample walk.
  const Motion walk = read_motion(std::string(MF_SOURCE_DIR) + "/samples/walk_keyframes.bvh");
  for (int i = 0; i < 12; ++i)
    write_motion(dir + "/clip" + std::to_string(i) + ".bvh", walk.slice(i, 40 + i), default_bvh_layout(walk.skeleton));
  const Dataset plain = training::load_training_data(dir, dir + "/cache", 0, 0.0, false, {}, false);
  const Dataset more = training::load_training_data(dir, dir + "/cache", 0, 0.0, true, {0.8, 1.25}, false);
  const size_t n = plain.train.size();
  ASSERT_GT(n, 0u);
  ASSERT_EQ(more.train.size(), 6 * n);  // originals, mirrors, then both at each speed
  EXPECT_EQ(more.validation.size(), plain.validation.size());
  EXPECT_EQ(more.train[n].name, plain.train[0].name + "#mirror");
  EXPECT_EQ(more.train[2 * n].name, plain.train[0].name + "@0.8x");
  EXPECT_EQ(more.train[5 * n].name, plain.train[0].name + "#mirror@1.25x");
  EXPECT_EQ(more.train[2 * n].motion.num_frames(), training::played_at_speed(plain.train[0].motion, 0.8).num_frames());
  for (double bad : {1.0, 0.3, 2.5, std::nan("")})
    EXPECT_THROW(training::load_training_data(dir, dir + "/cache", 0, 0.0, false, {bad}, false), InputError) << bad;
}

}  // namespace
}  // namespace mf
