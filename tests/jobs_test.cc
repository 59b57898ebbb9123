#include "tasks/methods/jobs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "prior/motion/errors.h"
#include "tasks/constraints/interpolation_fill.h"
#include "tasks/constraints/motion_constraints.h"
#include "tests/test_util.h"

namespace mf {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Runs `f`, expects an InputError and returns its message.
template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected InputError, nothing was thrown";
  return "";
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

void expect_same_motion(const Motion& a, const Motion& b) {
  ASSERT_EQ(a.num_frames(), b.num_frames());
  ASSERT_EQ(a.rotations.size(), b.rotations.size());
  for (int f = 0; f < a.num_frames(); ++f) EXPECT_EQ(a.root_positions[f], b.root_positions[f]) << f;
  for (size_t i = 0; i < a.rotations.size(); ++i) EXPECT_EQ(a.rotations[i].coeffs(), b.rotations[i].coeffs()) << i;
}

TEST(JobsTest, Methods) {
  const auto methods = available_methods();
  EXPECT_NE(std::find(methods.begin(), methods.end(), "interp"), methods.end());
  EXPECT_NE(std::find(methods.begin(), methods.end(), "zerovel"), methods.end());
  EXPECT_EQ(default_method(), "interp");  // without a model
  EXPECT_EQ(default_resample_method(), "quintic");
}

TEST(JobsTest, ValidateKeyframesAcceptsSortedUniqueInRange) {
  EXPECT_NO_THROW(validate_keyframes({0, 1}, 2));
  EXPECT_NO_THROW(validate_keyframes({0, 15, 30}, 31));
  EXPECT_NO_THROW(validate_keyframes({3, 7}, 31));  // need not include the ends
}

TEST(JobsTest, ValidateKeyframesRejectsWithClearMessages) {
  EXPECT_TRUE(contains(input_error([] { validate_keyframes({}, 10); }), "at least two keyframes"));
  EXPECT_TRUE(contains(input_error([] { validate_keyframes({4}, 10); }), "at least two keyframes"));
  std::string m = input_error([] { validate_keyframes({0, 10}, 10); });
  EXPECT_TRUE(contains(m, "keyframe 10 is out of range")) << m;
  EXPECT_TRUE(contains(m, "10 frames")) << m;
  m = input_error([] { validate_keyframes({-1, 5}, 10); });
  EXPECT_TRUE(contains(m, "keyframe -1 is out of range")) << m;
  m = input_error([] { validate_keyframes({0, 5, 3}, 10); });
  EXPECT_TRUE(contains(m, "increasing order")) << m;
  m = input_error([] { validate_keyframes({0, 5, 5, 9}, 10); });
  EXPECT_TRUE(contains(m, "keyframe 5 is given twice")) << m;
}

// The keys of constraints are checked in order by the same function, with the same words.
TEST(JobsTest, ConstraintKeysOutOfOrderSayWhatKeyframesSay) {
  std::string m = input_error([] { MotionConstraints::full_pose({0, 5, 3}).validate(10, 7); });
  EXPECT_TRUE(contains(m, "keyframes must be in increasing order (5 is followed by 3)")) << m;
  m = input_error([] { MotionConstraints::full_pose({0, 5, 5, 9}).validate(10, 7); });
  EXPECT_TRUE(contains(m, "keyframe 5 is given twice")) << m;
}

TEST(JobsTest, KnownFramesOutsideGap) {
  EXPECT_EQ(known_frames_outside_gap(10, 3, 6), (std::vector<int>{0, 1, 2, 6, 7, 8, 9}));
  EXPECT_EQ(known_frames_outside_gap(3, 1, 2), (std::vector<int>{0, 2}));
  EXPECT_EQ(known_frames_outside_gap(10, 1, 9), (std::vector<int>{0, 9}));
}

TEST(JobsTest, GapMustBeNonEmptyAndAwayFromTheEnds) {
  EXPECT_TRUE(contains(input_error([] { known_frames_outside_gap(10, 5, 5); }), "empty"));
  EXPECT_TRUE(contains(input_error([] { known_frames_outside_gap(10, 6, 5); }), "empty"));
  EXPECT_TRUE(contains(input_error([] { known_frames_outside_gap(10, 0, 5); }), "first frame"));
  EXPECT_TRUE(contains(input_error([] { known_frames_outside_gap(10, 3, 10); }), "last frame"));
  EXPECT_TRUE(contains(input_error([] { known_frames_outside_gap(10, 3, 12); }), "last frame"));
  EXPECT_TRUE(contains(input_error([] { known_frames_outside_gap(10, -2, 4); }), "first frame"));
}

TEST(JobsTest, ResampledFrameCountKeepsTheTimeSpan) {
  bool rounded = true;
  EXPECT_EQ(resampled_frame_count(61, 30, 60, &rounded), 121);
  EXPECT_FALSE(rounded);
  EXPECT_EQ(resampled_frame_count(61, 30, 24, &rounded), 49);
  EXPECT_FALSE(rounded);
  EXPECT_EQ(resampled_frame_count(61, 30, 15, &rounded), 31);
  EXPECT_EQ(resampled_frame_count(1, 30, 60, &rounded), 1);
  EXPECT_FALSE(rounded);
  // 60 * 23.3 / 30 + 1 = 47.6 -> 47, flagged.
  EXPECT_EQ(resampled_frame_count(61, 30, 23.3, &rounded), 47);
  EXPECT_TRUE(rounded);
  // 0.0333333 s per frame (a BVH frame time) still means 30 fps.
  EXPECT_EQ(resampled_frame_count(61, 1.0 / 0.0333333, 60, &rounded), 121);
  EXPECT_FALSE(rounded);
  EXPECT_EQ(resampled_frame_count(121, 60, 1.0 / 0.0333333, &rounded), 61);
  EXPECT_FALSE(rounded);
  EXPECT_EQ(resampled_frame_count(61, 30, 60, nullptr), 121);
}

TEST(JobsTest, ResampledFrameCountRejectsBadRates) {
  for (double bad : {0.0, -30.0, kNaN, kInf}) {
    EXPECT_THROW(resampled_frame_count(61, 30, bad, nullptr), InputError) << bad;
    EXPECT_THROW(resampled_frame_count(61, bad, 30, nullptr), InputError) << bad;
  }
  EXPECT_THROW(resampled_frame_count(0, 30, 60, nullptr), InputError);
  EXPECT_TRUE(contains(input_error([] { resampled_frame_count(1000000, 30, 3000, nullptr); }), "10000000 frames"));
  // A ratio that overflows (found by fuzz_capi_motion): infinite, or NaN for one frame.
  EXPECT_THROW(resampled_frame_count(1, 1e-300, 1e300, nullptr), InputError);
  EXPECT_THROW(resampled_frame_count(2, 1e-300, 1e300, nullptr), InputError);
}

TEST(JobsTest, RunInbetweenDispatchesByMethod) {
  const Motion in = test::random_motion(test::small_skeleton(), 21, 30.0, 21);
  const std::vector<int> keys = {0, 10, 20};
  expect_same_motion(run_inbetween(in, keys, "interp"), interpolate_motion(in, keys));
  expect_same_motion(run_inbetween(in, keys, ""), interpolate_motion(in, keys));
  expect_same_motion(run_inbetween(in, keys, "zerovel"), zero_velocity_motion(in, keys));
  const std::string m = input_error([&] { run_inbetween(in, keys, "magic"); });
  EXPECT_TRUE(contains(m, "unknown method 'magic'")) << m;
  EXPECT_TRUE(contains(m, "interp")) << m;
  EXPECT_THROW(run_inbetween(in, {0, 21}, "interp"), InputError);
  EXPECT_THROW(run_inbetween(in, {5}, "interp"), InputError);
}

TEST(JobsTest, RunFillNeverReadsTheGap) {
  const Motion truth = test::random_motion(test::small_skeleton(), 30, 30.0, 22);
  Motion in = truth;
  for (int f = 10; f < 20; ++f) {
    in.root_positions[f] = Eigen::Vector3d::Constant(kNaN);
    for (int j = 0; j < in.num_joints(); ++j) in.rotation(f, j).coeffs().setConstant(kNaN);
  }
  for (const std::string method : {"interp", "zerovel"}) {
    const Motion out = run_fill(in, 10, 20, method);
    ASSERT_EQ(out.num_frames(), 30);
    for (int f = 0; f < 30; ++f) {
      ASSERT_TRUE(out.root_positions[f].allFinite()) << method << " frame " << f;
      if (f < 10 || f >= 20) {
        EXPECT_EQ(out.root_positions[f], truth.root_positions[f]);
      }
    }
    for (const auto& q : out.rotations) ASSERT_TRUE(q.coeffs().allFinite()) << method;
  }
  expect_same_motion(run_fill(in, 10, 20, "zerovel"), zero_velocity_motion(in, known_frames_outside_gap(30, 10, 20)));
  EXPECT_THROW(run_fill(in, 0, 20, "interp"), InputError);
  EXPECT_THROW(run_fill(in, 10, 30, "interp"), InputError);
  EXPECT_THROW(run_fill(in, 10, 10, "interp"), InputError);
}

TEST(JobsTest, RunResampleWarnsOnlyWhenRounding) {
  const Motion in = test::random_motion(test::small_skeleton(), 61, 30.0, 23);
  std::vector<std::string> warnings;
  const Motion up = run_resample(in, 60.0, "interp", &warnings);
  EXPECT_EQ(up.num_frames(), 121);
  EXPECT_DOUBLE_EQ(up.fps, 60.0);
  EXPECT_TRUE(warnings.empty());
  const Motion odd = run_resample(in, 23.3, "zerovel", &warnings);
  EXPECT_EQ(odd.num_frames(), 47);
  EXPECT_DOUBLE_EQ(odd.fps, 23.3);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_TRUE(contains(warnings[0], "rounded down to 47 frames")) << warnings[0];
  EXPECT_NO_THROW(run_resample(in, 23.3, "interp", nullptr));
  EXPECT_THROW(run_resample(in, 0.0, "interp", nullptr), InputError);
  EXPECT_THROW(run_resample(in, kNaN, "interp", nullptr), InputError);
  EXPECT_THROW(run_resample(in, 60.0, "nope", nullptr), InputError);
}

}  // namespace
}  // namespace mf
