// The prior's evaluation (bench/prior_eval.h): metrics on hand-computed cases
// and the four tasks on a tiny untrained model and synthetic clips.
#include "bench/prior_eval.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "prior/model/nemf.h"
#include "prior/model/representation.h"
#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "tests/runtime_test_util.h"
#include "tests/test_util.h"

namespace mf::bench {
namespace {

constexpr double kDeg = M_PI / 180.0;

Clip make_clip(const std::string& name, Motion motion) {
  Clip c;
  c.name = name;
  c.motion = std::move(motion);
  return c;
}

TEST(PriorEval, IdenticalMotionsScoreZero) {
  const Motion m = test::random_motion(test::small_skeleton(), 20, 30.0, 1);
  ReconAccumulator acc;
  acc.add(m, m);
  const ReconMetrics r = acc.summary();
  EXPECT_EQ(r.windows, 1);
  EXPECT_EQ(r.frames, 20);
  EXPECT_EQ(r.mre_deg, 0.0);
  EXPECT_EQ(r.mpe_cm, 0.0);
  EXPECT_EQ(r.moe_deg, 0.0);
  EXPECT_EQ(r.mte_cm, 0.0);
  EXPECT_EQ(r.fde_cm, 0.0);
  EXPECT_THROW(acc.add(m, m.slice(0, 10)), InputError);
}

TEST(PriorEval, KnownRotationOffsetGivesItsAngle) {
  const Motion truth = test::random_motion(test::small_skeleton(), 12, 30.0, 2);
  const int J = truth.num_joints();
  // 10 degrees about x on one leaf joint (index J - 1: a foot, whose rotation
  // moves no joint position): MRE = 10 / (J - 1), nothing else changes.
  const int leaf = J - 1;
  ASSERT_TRUE(truth.skeleton.children()[leaf].empty());
  Motion pred = truth;
  const Eigen::Quaterniond tilt(Eigen::AngleAxisd(10.0 * kDeg, Eigen::Vector3d::UnitX()));
  for (int f = 0; f < 12; ++f) pred.rotation(f, leaf) = pred.rotation(f, leaf) * tilt;
  ReconAccumulator a;
  a.add(truth, pred);
  EXPECT_NEAR(a.summary().mre_deg, 10.0 / (J - 1), 1e-9);
  EXPECT_NEAR(a.summary().mpe_cm, 0.0, 1e-9);
  EXPECT_NEAR(a.summary().moe_deg, 0.0, 1e-9);
  EXPECT_NEAR(a.summary().fde_cm, 0.0, 1e-9);

  // The root turned by 30 degrees about +Y (world): MOE = 30; each
  // root-relative vector v moves by 2 sin(15 deg) |v_xz|; the root stays put.
  Motion turned = truth;
  const Eigen::Quaterniond yaw(Eigen::AngleAxisd(30.0 * kDeg, Eigen::Vector3d::UnitY()));
  for (int f = 0; f < 12; ++f) turned.rotation(f, 0) = yaw * truth.rotation(f, 0);
  const GlobalPose p = forward_kinematics(truth);
  double expect_mpe = 0.0, expect_fde = 0.0;
  for (int f = 0; f < 12; ++f) {
    for (int j = 1; j < J; ++j) {
      const Eigen::Vector3d v = p.position(f, j) - p.position(f, 0);
      const double d = 100.0 * 2.0 * std::sin(15.0 * kDeg) * std::hypot(v.x(), v.z());
      expect_mpe += d / (12.0 * (J - 1));
      if (f == 11) expect_fde += d / J;
    }
  }
  ReconAccumulator b;
  b.add(truth, turned);
  EXPECT_NEAR(b.summary().moe_deg, 30.0, 1e-9);
  EXPECT_NEAR(b.summary().mre_deg, 0.0, 1e-9);
  EXPECT_NEAR(b.summary().mpe_cm, expect_mpe, 1e-9);
  EXPECT_NEAR(b.summary().mte_cm, 0.0, 1e-9);
  EXPECT_NEAR(b.summary().fde_cm, expect_fde, 1e-9);
}

TEST(PriorEval, RootOffsetGivesTranslationAndFinalErrors) {
  const Motion truth = test::random_motion(test::small_skeleton(), 8, 30.0, 3);
  Motion pred = truth;
  for (auto& r : pred.root_positions) r += Eigen::Vector3d(0.03, 0.0, 0.04);  // 5 cm
  ReconAccumulator acc;
  acc.add(truth, pred);
  acc.add(truth, truth);  // a second, perfect window halves the window means
  const ReconMetrics m = acc.summary();
  EXPECT_EQ(m.windows, 2);
  EXPECT_NEAR(m.mte_cm, 2.5, 1e-9);
  EXPECT_NEAR(m.fde_cm, 2.5, 1e-9);
  EXPECT_NEAR(m.mpe_cm, 0.0, 1e-9);
  EXPECT_NEAR(m.mre_deg, 0.0, 1e-9);
}

TEST(PriorEval, AccelerationOfAUniformlyAcceleratedMotion) {
  const Motion r = test::random_motion(test::small_skeleton(), 30, 60.0, 4);
  Motion m = r;
  const Eigen::Vector3d accel(1.5, 0.0, -2.0);  // |a| = 2.5 m/s^2
  for (int f = 0; f < 30; ++f) {
    for (int j = 0; j < m.num_joints(); ++j) m.rotation(f, j) = r.rotation(0, j);
    const double t = f / 60.0;
    m.root_positions[f] = Eigen::Vector3d(0.1, 0.9, 0.2) + Eigen::Vector3d(0.5, 0, 0) * t + 0.5 * accel * t * t;
  }
  EXPECT_NEAR(mean_joint_acceleration(m), 2.5, 1e-6);
  std::vector<int> frames{0, 5, 29};  // 0 and 29 have no second difference
  EXPECT_NEAR(mean_joint_acceleration(m, &frames), 2.5, 1e-6);
  EXPECT_EQ(mean_joint_acceleration(m.slice(0, 2)), 0.0);
  // The pose does not move relative to the root.
  EXPECT_NEAR(mean_joint_acceleration(m, nullptr, true), 0.0, 1e-6);
  // A pose swinging on a still root: root-relative equals global.
  Motion swing = r;
  for (auto& p : swing.root_positions) p = Eigen::Vector3d(0, 0.9, 0);
  EXPECT_NEAR(mean_joint_acceleration(swing, nullptr, true) * (swing.num_joints() - 1),
              mean_joint_acceleration(swing) * swing.num_joints(), 1e-6);
}

TEST(PriorEval, JointLimitsCountFramesBeyondThePercentile) {
  const Skeleton s = test::small_skeleton();
  // Joint 1 turns about x by 0, 1, ..., 99 degrees; every other joint holds identity.
  Motion m = Motion::identity(s, 100, 30.0);
  for (int f = 0; f < 100; ++f) m.rotation(f, 1) = Eigen::Quaterniond(Eigen::AngleAxisd(f * kDeg, Eigen::Vector3d::UnitX()));
  const JointLimits lim = compute_joint_limits({make_clip("a", m)}, 0.9);
  // The mean of a uniform arc is its middle (49.5 deg); the 90th percentile of
  // |angle - 49.5| over the 100 frames lies near 45 deg.
  EXPECT_NEAR(geodesic_angle(lim.mean[1], Eigen::Quaterniond(Eigen::AngleAxisd(49.5 * kDeg, Eigen::Vector3d::UnitX()))),
              0.0, 1e-9);
  EXPECT_NEAR(lim.limit_rad[1] / kDeg, 45.0, 0.6);
  EXPECT_NEAR(lim.limit_rad[2], 0.0, 1e-12);
  std::vector<long> exceed;
  long frames = 0;
  count_limit_exceedances(m, lim, &exceed, &frames);
  EXPECT_EQ(frames, 100);
  EXPECT_NEAR(static_cast<double>(exceed[1]), 10.0, 2.0);
  EXPECT_EQ(exceed[2], 0);
  EXPECT_THROW(compute_joint_limits({}), InputError);
}

TEST(PriorEval, TasksRunOnATinyModel) {
  const auto model = std::make_shared<const NemfModel>(test::tiny_prior());
  const runtime::NemfRuntime rt = test::runtime_of(*model);
  const Skeleton s = test::small_skeleton();
  std::vector<Clip> train = {make_clip("t1", test::random_motion(s, 120, 30.0, 11)),
                             make_clip("t2", test::random_motion(s, 90, 30.0, 12))};
  const EvalStats stats = compute_eval_stats(train);
  // 70 frames: 2 full 32-frame windows; 20: a short clip; 100: 3 full windows.
  std::vector<Clip> val = {make_clip("v1", test::random_motion(s, 70, 30.0, 21)),
                           make_clip("v2", test::random_motion(s, 20, 30.0, 22)),
                           make_clip("v3", test::random_motion(s, 100, 30.0, 23))};
  PriorEvalOptions options;
  options.samples = 3;

  const ReconResult recon = run_recon(*model, rt, val, stats, options);
  EXPECT_EQ(recon.window, 32);
  EXPECT_EQ(recon.full.windows, 5);
  EXPECT_EQ(recon.full.frames, 160);
  EXPECT_EQ(recon.short_.windows, 1);
  EXPECT_EQ(recon.short_.frames, 20);
  EXPECT_GT(recon.full.mre_deg, 0.0);
  EXPECT_TRUE(std::isfinite(recon.full.fde_cm));
  EXPECT_NE(format_recon(recon).find("| full (32 frames) | 5 | 160 |"), std::string::npos) << format_recon(recon);

  const FpsResult fps = run_fps(rt, val, options);
  ASSERT_EQ(fps.rows.size(), 4u);
  EXPECT_EQ(fps.rows[0].windows, 5);
  EXPECT_NEAR(fps.rows[0].accel, fps.rows[0].accel_30, 1e-9);  // the 30 fps row is its own reference
  for (const FpsRow& row : fps.rows) EXPECT_TRUE(std::isfinite(row.accel));
  EXPECT_NE(format_fps(fps).find("| 240 | 5 |"), std::string::npos);

  const SeamResult seams = run_seams(rt, val, options);
  EXPECT_EQ(seams.clips, 2);  // v1 and v3 are longer than a window
  EXPECT_EQ(seams.near.frames + seams.elsewhere.frames, 170);
  EXPECT_GT(seams.near.frames, 0);
  EXPECT_GT(seams.elsewhere.frames, 0);
  EXPECT_NE(format_seams(seams, 5).find("within 5 of a window boundary"), std::string::npos);

  const SampleResult sample = run_sample(*model, val, train, stats, options);
  EXPECT_EQ(sample.samples, 3);
  EXPECT_EQ(sample.truth_windows, 5);
  ASSERT_EQ(sample.sample_fraction.size(), static_cast<size_t>(s.num_joints()));
  ASSERT_EQ(sample.truth_fraction.size(), static_cast<size_t>(s.num_joints()));
  for (double f : sample.sample_fraction) EXPECT_TRUE(f >= 0.0 && f <= 1.0);
  EXPECT_NE(format_sample(sample).find("| joint | limit (deg) |"), std::string::npos);
  // A fixed seed gives the same samples.
  const SampleResult again = run_sample(*model, val, train, stats, options);
  EXPECT_EQ(again.skating_cm, sample.skating_cm);
}

}  // namespace
}  // namespace mf::bench
