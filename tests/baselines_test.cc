#include "tasks/constraints/interpolation_fill.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "prior/motion/errors.h"
#include "tests/test_util.h"

namespace mf {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Overwrites every frame not in `known` with NaN, so a baseline that reads an
// unknown frame produces a non-finite output.
Motion poison_unknown(Motion m, const std::vector<int>& known) {
  for (int f = 0; f < m.num_frames(); ++f) {
    bool is_known = false;
    for (int k : known) is_known |= k == f;
    if (is_known) continue;
    m.root_positions[f] = Eigen::Vector3d::Constant(kNaN);
    for (int j = 0; j < m.num_joints(); ++j) m.rotation(f, j) = Eigen::Quaterniond(kNaN, kNaN, kNaN, kNaN);
  }
  return m;
}

// Exact (bitwise-equal values) copy of frame a of `x` in frame b of `y`.
void expect_frame_equal(const Motion& x, int a, const Motion& y, int b) {
  EXPECT_EQ(x.root_positions[a], y.root_positions[b]) << "frames " << a << " / " << b;
  for (int j = 0; j < x.num_joints(); ++j)
    EXPECT_EQ(x.rotation(a, j).coeffs(), y.rotation(b, j).coeffs()) << "frames " << a << " / " << b << ", joint " << j;
}

double angle_between(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return 2.0 * std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized()))));
}

Eigen::Quaterniond about_y(double degrees) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(degrees * 3.14159265358979323846 / 180.0, Eigen::Vector3d::UnitY()));
}

// A one-joint motion with the given root positions and rotations.
Motion one_joint(const std::vector<Eigen::Vector3d>& positions, const std::vector<Eigen::Quaterniond>& rotations,
                 double fps = 30.0) {
  Skeleton s;
  s.names = {"Hips"};
  s.parents = {-1};
  s.offsets = {Eigen::Vector3d::Zero()};
  Motion m = Motion::identity(s, static_cast<int>(positions.size()), fps);
  m.root_positions = positions;
  m.rotations = rotations;
  return m;
}

TEST(BaselinesTest, InterpolateReadsOnlyKnownFramesAndCopiesThemExactly) {
  const Motion truth = test::random_motion(test::small_skeleton(), 31, 30.0, 7);
  const std::vector<int> known = {0, 4, 10, 30};
  const Motion out = interpolate_motion(poison_unknown(truth, known), known);
  ASSERT_EQ(out.num_frames(), 31);
  ASSERT_EQ(out.num_joints(), truth.num_joints());
  EXPECT_DOUBLE_EQ(out.fps, 30.0);
  EXPECT_TRUE(test::all_finite(out));
  for (int k : known) expect_frame_equal(truth, k, out, k);
}

TEST(BaselinesTest, ZeroVelocityReadsOnlyKnownFramesAndCopiesThemExactly) {
  const Motion truth = test::random_motion(test::small_skeleton(), 25, 30.0, 8);
  const std::vector<int> known = {3, 11, 20};
  const Motion out = zero_velocity_motion(poison_unknown(truth, known), known);
  ASSERT_EQ(out.num_frames(), 25);
  EXPECT_TRUE(test::all_finite(out));
  for (int f = 0; f < 25; ++f) {
    const int source = f < 11 ? 3 : f < 20 ? 11 : 20;  // the last known frame before f, else the first
    expect_frame_equal(truth, source, out, f);
  }
}

TEST(BaselinesTest, InterpolateMidpointIsLerpAndSlerpByHand) {
  // Frame 0: origin, identity. Frame 4: (4, 8, -12), 90 degrees about Y.
  const Motion in = one_joint({{0, 0, 0}, {kNaN, 0, 0}, {kNaN, 0, 0}, {kNaN, 0, 0}, {4, 8, -12}},
                              {about_y(0), about_y(0), about_y(0), about_y(0), about_y(90)});
  const Motion out = interpolate_motion(in, {0, 4});
  // t = 0.5: root (2, 4, -6), 45 degrees; t = 0.25: (1, 2, -3), 22.5 degrees.
  EXPECT_NEAR((out.root_positions[2] - Eigen::Vector3d(2, 4, -6)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((out.root_positions[1] - Eigen::Vector3d(1, 2, -3)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((out.root_positions[3] - Eigen::Vector3d(3, 6, -9)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(angle_between(out.rotation(2, 0), about_y(45)), 0.0, 1e-9);
  EXPECT_NEAR(angle_between(out.rotation(1, 0), about_y(22.5)), 0.0, 1e-9);
  EXPECT_NEAR(angle_between(out.rotation(3, 0), about_y(67.5)), 0.0, 1e-9);
  EXPECT_NEAR(out.rotation(2, 0).norm(), 1.0, 1e-12);
}

TEST(BaselinesTest, InterpolateTakesTheShortestPath) {
  // 170 degrees and -170 degrees about Y are 20 degrees apart (their
  // quaternions have a negative dot product); the midpoint is 180 degrees, not 0.
  const Motion in = one_joint({{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, {about_y(170), about_y(0), about_y(-170)});
  ASSERT_LT(about_y(170).dot(about_y(-170)), 0.0);
  const Motion out = interpolate_motion(in, {0, 2});
  EXPECT_NEAR(angle_between(out.rotation(1, 0), about_y(180)), 0.0, 1e-9);
}

TEST(BaselinesTest, InterpolateHoldsTheEndsOutsideTheKnownFrames) {
  const Motion truth = test::random_motion(test::small_skeleton(), 7, 30.0, 9);
  const std::vector<int> known = {2, 4};
  const Motion out = interpolate_motion(poison_unknown(truth, known), known);
  expect_frame_equal(truth, 2, out, 0);
  expect_frame_equal(truth, 2, out, 1);
  expect_frame_equal(truth, 4, out, 5);
  expect_frame_equal(truth, 4, out, 6);
}

TEST(BaselinesTest, ResampleTo60KeepsTheTimeSpanAndInputFrames) {
  const Motion in = test::random_motion(test::small_skeleton(), 31, 30.0, 10);
  const Motion out = resample_interpolate(in, 60.0, 61);
  ASSERT_EQ(out.num_frames(), 61);
  EXPECT_DOUBLE_EQ(out.fps, 60.0);
  // Every even output frame is an input frame (times 2k/60 = k/30), copied exactly,
  // including both endpoints.
  for (int k = 0; k <= 30; ++k) expect_frame_equal(in, k, out, 2 * k);
  // Odd frames are midpoints.
  const Eigen::Vector3d mid = 0.5 * (in.root_positions[3] + in.root_positions[4]);
  EXPECT_NEAR((out.root_positions[7] - mid).norm(), 0.0, 1e-12);
  for (int j = 0; j < in.num_joints(); ++j) {
    const double half = angle_between(in.rotation(3, j), in.rotation(4, j)) / 2;
    EXPECT_NEAR(angle_between(out.rotation(7, j), in.rotation(3, j)), half, 1e-9);
    EXPECT_NEAR(angle_between(out.rotation(7, j), in.rotation(4, j)), half, 1e-9);
  }
}

TEST(BaselinesTest, ResampleTo24InterpolatesAtFractionalPositions) {
  // 31 frames at 30 fps -> 25 frames at 24 fps; output frame i sits at input
  // position 1.25 i.
  const Motion in = one_joint(
      [] {
        std::vector<Eigen::Vector3d> p;
        for (int f = 0; f < 31; ++f) p.emplace_back(f * 0.1, 1.0, -f * 0.2);
        return p;
      }(),
      [] {
        std::vector<Eigen::Quaterniond> q;
        for (int f = 0; f < 31; ++f) q.push_back(about_y(10.0 * f));  // far enough apart for true SLERP
        return q;
      }());
  const Motion out = resample_interpolate(in, 24.0, 25);
  ASSERT_EQ(out.num_frames(), 25);
  EXPECT_DOUBLE_EQ(out.fps, 24.0);
  for (int i = 0; i < 25; ++i) {
    const double s = 1.25 * i;
    EXPECT_NEAR((out.root_positions[i] - Eigen::Vector3d(0.1 * s, 1.0, -0.2 * s)).norm(), 0.0, 1e-12) << i;
    EXPECT_NEAR(angle_between(out.rotation(i, 0), about_y(10.0 * s)), 0.0, 1e-9) << i;
  }
  expect_frame_equal(in, 0, out, 0);
  expect_frame_equal(in, 5, out, 4);
  expect_frame_equal(in, 30, out, 24);  // the last output frame is the last input frame
}

TEST(BaselinesTest, ResampleCubicFollowsCurvedMotionThatInterpolationCuts) {
  // 21 frames at 15 fps -> 41 at 30: a root on a parabola and a joint turning
  // about y at an accelerating rate. Catmull-Rom reproduces quadratics exactly
  // away from the ends (its tangents are central differences); LERP and SLERP
  // cut the curve.
  const auto x = [](double s) { return 0.02 * s * s; };
  const auto angle = [](double s) { return 0.3 * s * s; };  // degrees (angle_between gives radians)
  const Motion in = one_joint(
      [&] {
        std::vector<Eigen::Vector3d> p;
        for (int f = 0; f < 21; ++f) p.emplace_back(x(f), 1.0, 0.1 * f);
        return p;
      }(),
      [&] {
        std::vector<Eigen::Quaterniond> q;
        for (int f = 0; f < 21; ++f) q.push_back(about_y(angle(f)));
        return q;
      }(),
      15.0);
  const Motion cubic = resample_cubic(in, 30.0, 41), lerp = resample_interpolate(in, 30.0, 41);
  ASSERT_EQ(cubic.num_frames(), 41);
  EXPECT_DOUBLE_EQ(cubic.fps, 30.0);
  for (int k = 0; k <= 20; ++k) expect_frame_equal(in, k, cubic, 2 * k);
  for (int i = 3; i < 38; i += 2) {  // midpoints with two input frames on each side
    const double s = i / 2.0;
    EXPECT_NEAR((cubic.root_positions[i] - Eigen::Vector3d(x(s), 1.0, 0.1 * s)).norm(), 0.0, 1e-12) << i;
    EXPECT_NEAR(lerp.root_positions[i].x() - x(s), 0.005, 1e-12) << i;  // the chord's sag, 0.02 / 4
    const double cubic_deg = angle_between(cubic.rotation(i, 0), about_y(angle(s)));
    const double lerp_deg = angle_between(lerp.rotation(i, 0), about_y(angle(s)));
    EXPECT_NEAR(lerp_deg, 0.075 * 3.14159265358979323846 / 180.0, 1e-9) << i;  // radians
    EXPECT_LT(cubic_deg, 0.2 * lerp_deg) << i;
  }
  EXPECT_THROW(resample_cubic(in, 0.0, 3), InputError);
  EXPECT_THROW(resample_cubic(in, 30.0, 0), InputError);
}

TEST(BaselinesTest, ResampleQuinticReproducesQuinticsThatTheSplineMisses) {
  // 21 frames at 10 fps -> 61 at 30 (two new frames between input frames, at
  // t = 1/3 and 2/3): a root on a polynomial of degree 5. Away from the ends
  // (two input frames before, three after) the quintic reproduces it to
  // rounding; Catmull-Rom, exact only up to quadratics, does not.
  const auto x = [](double s) { return 1e-5 * std::pow(s - 10.0, 5) + 0.01 * std::pow(s, 3); };
  std::vector<Eigen::Vector3d> p;
  std::vector<Eigen::Quaterniond> q;
  for (int f = 0; f < 21; ++f) {
    p.emplace_back(x(f), 1.0, 0.1 * f);
    q.push_back(about_y(0.5 * f));
  }
  const Motion in = one_joint(p, q, 10.0);
  const Motion quintic = resample_quintic(in, 30.0, 61), cubic = resample_cubic(in, 30.0, 61);
  ASSERT_EQ(quintic.num_frames(), 61);
  EXPECT_DOUBLE_EQ(quintic.fps, 30.0);
  for (int k = 0; k <= 20; ++k) expect_frame_equal(in, k, quintic, 3 * k);
  double cubic_worst = 0;
  for (int i = 7; i < 52; ++i) {  // between input frames 2 and 17
    if (i % 3 == 0) continue;
    const double s = i / 3.0;
    EXPECT_NEAR(quintic.root_positions[i].x(), x(s), 1e-10) << i;
    EXPECT_NEAR(quintic.root_positions[i].z(), 0.1 * s, 1e-12) << i;
    cubic_worst = std::max(cubic_worst, std::abs(cubic.root_positions[i].x() - x(s)));
    // A joint turning at a constant rate: the quaternion components are
    // sinusoids, which the normalised blend follows to well under a degree.
    EXPECT_LT(angle_between(quintic.rotation(i, 0), about_y(0.5 * s)), 1e-4) << i;
  }
  EXPECT_GT(cubic_worst, 1e-3);
  EXPECT_THROW(resample_quintic(in, 0.0, 3), InputError);
  EXPECT_THROW(resample_quintic(in, 30.0, 0), InputError);
}

TEST(BaselinesTest, ResampleZeroVelocityHoldsThePreviousInputFrame) {
  const Motion in = test::random_motion(test::small_skeleton(), 31, 30.0, 11);
  const Motion out = resample_zero_velocity(in, 24.0, 25);
  ASSERT_EQ(out.num_frames(), 25);
  EXPECT_DOUBLE_EQ(out.fps, 24.0);
  for (int i = 0; i < 25; ++i) expect_frame_equal(in, static_cast<int>(std::floor(1.25 * i)), out, i);
  const Motion up = resample_zero_velocity(in, 60.0, 61);
  for (int i = 0; i < 61; ++i) expect_frame_equal(in, i / 2, up, i);
}

TEST(BaselinesTest, ResampleSnapsFrameTimesPrintedWithSixDigits) {
  // A BVH frame time of 0.0333333 s gives fps 30.00003: output frames that
  // coincide with input frames must still copy them, not blend in the next one.
  Motion in = test::random_motion(test::small_skeleton(), 11, 1.0 / 0.0333333, 12);
  const Motion out = resample_interpolate(in, 60.0, 21);
  for (int k = 0; k <= 10; ++k) expect_frame_equal(in, k, out, 2 * k);
}

TEST(BaselinesTest, BadArgumentsThrowInputError) {
  const Motion in = test::random_motion(test::small_skeleton(), 5, 30.0, 13);
  EXPECT_THROW(interpolate_motion(in, {}), InputError);
  EXPECT_THROW(interpolate_motion(in, {0, 5}), InputError);
  EXPECT_THROW(interpolate_motion(in, {-1, 2}), InputError);
  EXPECT_THROW(zero_velocity_motion(in, {3, 1}), InputError);
  EXPECT_THROW(resample_interpolate(in, 0.0, 3), InputError);
  EXPECT_THROW(resample_interpolate(in, 60.0, 0), InputError);
  EXPECT_THROW(resample_zero_velocity(in, std::numeric_limits<double>::infinity(), 3), InputError);
}

}  // namespace
}  // namespace mf
