// Metrics of the benchmark (bench/metrics.h) on tiny hand-computed cases.
#include "bench/metrics.h"

#include <gtest/gtest.h>

#include <cmath>

#include "prior/data/dataset.h"
#include "prior/motion/errors.h"
#include "tests/test_util.h"

namespace mf::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Quaterniond about(const Eigen::Vector3d& axis, double degrees) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(degrees * kPi / 180.0, axis.normalized()));
}

// A pose of `frames` frames and `joints` joints at the origin, identity rotations.
GlobalPose zero_pose(int frames, int joints) {
  GlobalPose p;
  p.frames = frames;
  p.joints = joints;
  p.positions.assign(static_cast<size_t>(frames) * joints, Eigen::Vector3d::Zero());
  p.rotations.assign(static_cast<size_t>(frames) * joints, Eigen::Quaterniond::Identity());
  return p;
}

Eigen::Vector3d& pos(GlobalPose& p, int f, int j) { return p.positions[static_cast<size_t>(f) * p.joints + j]; }

// Root plus one child 0.5 m along the root's +Z; the child is named `child`.
Skeleton two_joint_skeleton(const std::string& child, const Eigen::Vector3d& offset) {
  Skeleton s;
  s.names = {"Hips", child};
  s.parents = {-1, 0};
  s.offsets = {Eigen::Vector3d::Zero(), offset};
  return s;
}

TEST(MetricsTest, CanonicalisationPutsAnchorRootAtOriginFacingX) {
  Motion m = Motion::identity(two_joint_skeleton("Spine", {0, 0, 0.5}), 3, 30.0);
  for (int f = 0; f < 3; ++f) {
    // Facing +Z (identity root), walking forward 1 m per frame from (3, 1, 4).
    m.root_positions[f] = Eigen::Vector3d(3, 1, 4 + f);
  }
  const Motion c = canonicalise(m, 1);
  // Anchor frame 1: root at the origin on the ground plane, height kept.
  EXPECT_NEAR((c.root_positions[1] - Eigen::Vector3d(0, 1, 0)).norm(), 0.0, 1e-12);
  // Forward (+Z) became +X, so walking forward moves along +X.
  EXPECT_NEAR((c.root_positions[0] - Eigen::Vector3d(-1, 1, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((c.root_positions[2] - Eigen::Vector3d(1, 1, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((c.rotation(1, 0) * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitX()).norm(), 0.0, 1e-12);
  // The child's global position (0.5 m ahead of the root) follows.
  const GlobalPose g = forward_kinematics(c);
  EXPECT_NEAR((g.position(1, 1) - Eigen::Vector3d(0.5, 1, 0)).norm(), 0.0, 1e-12);
  // Non-root local rotations are untouched.
  EXPECT_TRUE(c.rotation(1, 1).isApprox(m.rotation(1, 1)));
}

TEST(MetricsTest, CanonicalisationUsesHeadingOfForwardAxis) {
  Motion m = Motion::identity(two_joint_skeleton("Spine", {0, 0, 0.5}), 1, 30.0);
  // Root yawed by 90 degrees about +Y and pitched 30 degrees: its +Z points to
  // +X (tilted down); with +X as the forward axis it points to -Z.
  m.rotation(0, 0) = about(Eigen::Vector3d::UnitY(), 90) * about(Eigen::Vector3d::UnitX(), 30);
  m.root_positions[0] = Eigen::Vector3d(-2, 0.9, 5);
  const Motion c = canonicalise(m, 0);
  const Eigen::Vector3d f = c.rotation(0, 0) * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(f.z(), 0.0, 1e-12);
  EXPECT_GT(f.x(), 0.0);
  EXPECT_NEAR(f.y(), -std::sin(30 * kPi / 180), 1e-12);  // the pitch is kept

  const RigidTransform t = canonical_transform(m, 0, Eigen::Vector3d::UnitX());
  // Forward -Z must map to +X: a rotation of -90 degrees about Y.
  EXPECT_NEAR((t.rotation * Eigen::Vector3d(0, 0, -1) - Eigen::Vector3d::UnitX()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((t.apply(m.root_positions[0]) - Eigen::Vector3d(0, 0.9, 0)).norm(), 0.0, 1e-12);

  EXPECT_THROW(canonical_transform(m, 1), InputError);
  EXPECT_THROW(canonical_transform(m, -1), InputError);
}

TEST(MetricsTest, FindsFootJointsByName) {
  Skeleton s;
  s.names = {"Hips", "Foot_L", "Toes_L", "LeftAnkle", "LeftToeBase", "LowerLeg_L", "FOOT_R"};
  s.parents = {-1, 0, 1, 0, 3, 0, 0};
  s.offsets.assign(7, Eigen::Vector3d(0, -0.1, 0));
  const std::vector<FootJoint> feet = metric_foot_joints(s);
  ASSERT_EQ(feet.size(), 5u);
  EXPECT_EQ(feet[0].joint, 1);
  EXPECT_EQ(feet[0].threshold_cm, 8.0);
  EXPECT_EQ(feet[1].joint, 2);
  EXPECT_EQ(feet[1].threshold_cm, 4.0);
  EXPECT_EQ(feet[2].joint, 3);
  EXPECT_EQ(feet[2].threshold_cm, 8.0);
  EXPECT_EQ(feet[3].joint, 4);
  EXPECT_EQ(feet[3].threshold_cm, 4.0);
  EXPECT_EQ(feet[4].joint, 6);
}

TEST(MetricsTest, QuantileMatchesNumpyLinear) {
  EXPECT_DOUBLE_EQ(quantile({5, 1, 4, 2, 3}, 0.05), 1.2);  // position 0.2 between 1 and 2
  EXPECT_DOUBLE_EQ(quantile({4, 1, 3, 2}, 0.5), 2.5);
  EXPECT_DOUBLE_EQ(quantile({7}, 0.05), 7.0);
  EXPECT_THROW(quantile({}, 0.5), InputError);
}

TEST(MetricsTest, L2PIsNormOfZScoredDifference) {
  EvalStats stats;
  stats.position_mean.assign(6, 0.3);
  stats.position_std = {2, 2, 2, 2, 2, 4};
  GlobalPose truth = zero_pose(2, 2), pred = zero_pose(2, 2);
  pos(pred, 1, 1) = Eigen::Vector3d(0.3, 0.4, 0.0);  // z-scored (0.15, 0.2, 0): norm 0.25
  EXPECT_NEAR(l2p(truth, pred, {1}, stats), 0.25, 1e-12);
  EXPECT_NEAR(l2p(truth, pred, {0, 1}, stats), 0.125, 1e-12);
  EXPECT_NEAR(l2p(truth, pred, {1}, stats, L2PAxes::Horizontal), 0.15, 1e-12);
  EXPECT_NEAR(l2p(truth, pred, {1}, stats, L2PAxes::Vertical), 0.2, 1e-12);
  pos(pred, 0, 1) = Eigen::Vector3d(0.0, 0.0, 1.2);  // z-scored 0.3
  EXPECT_NEAR(l2p(truth, pred, {0, 1}, stats), 0.275, 1e-12);
  EXPECT_NEAR(l2p(truth, truth, {0, 1}, stats), 0.0, 1e-15);
  EXPECT_THROW(l2p(truth, pred, {2}, stats), InputError);
}

TEST(MetricsTest, L2QIgnoresSignFlipsAndMeasuresQuaternionDistance) {
  GlobalPose truth = zero_pose(2, 1), pred = zero_pose(2, 1);
  // Frame 1: 90 degrees about X; |(c - 1, s, 0, 0)| = sqrt(2 - 2 cos 45) = sqrt(2 - sqrt 2).
  pred.rotations[1] = about(Eigen::Vector3d::UnitX(), 90);
  const double expected = std::sqrt(2.0 - std::sqrt(2.0));
  std::vector<double> tq = continuous_quaternions(truth);
  std::vector<double> pq = continuous_quaternions(pred, &truth);
  EXPECT_NEAR(l2q(tq, pq, 1, {1}), expected, 1e-12);
  EXPECT_NEAR(l2q(tq, pq, 1, {0, 1}), expected / 2, 1e-12);

  // The same prediction with every sign flipped scores the same.
  for (auto& q : pred.rotations) q.coeffs() = -q.coeffs();
  pq = continuous_quaternions(pred, &truth);
  EXPECT_NEAR(l2q(tq, pq, 1, {0, 1}), expected / 2, 1e-12);
  EXPECT_NEAR(pq[0], 1.0, 1e-12);  // frame 0 took the truth's hemisphere

  // A truth stored with w < 0 at frame 0 is flipped to w >= 0; the prediction
  // follows it whatever sign it was stored with.
  GlobalPose truth2 = zero_pose(2, 1), pred2 = zero_pose(2, 1);
  truth2.rotations[0] = Eigen::Quaterniond(-about(Eigen::Vector3d::UnitZ(), 40).coeffs());
  truth2.rotations[1] = Eigen::Quaterniond(-about(Eigen::Vector3d::UnitZ(), 50).coeffs());
  pred2.rotations[0] = about(Eigen::Vector3d::UnitZ(), 40);
  pred2.rotations[1] = about(Eigen::Vector3d::UnitZ(), 50);
  tq = continuous_quaternions(truth2);
  pq = continuous_quaternions(pred2, &truth2);
  EXPECT_GT(tq[0], 0.0);
  EXPECT_NEAR(l2q(tq, pq, 1, {0, 1}), 0.0, 1e-12);
  for (auto& q : pred2.rotations) q.coeffs() = -q.coeffs();
  pq = continuous_quaternions(pred2, &truth2);
  EXPECT_NEAR(l2q(tq, pq, 1, {0, 1}), 0.0, 1e-12);
}

TEST(MetricsTest, ContinuousQuaternionsRemoveSignJumps) {
  GlobalPose p = zero_pose(3, 1);
  p.rotations[0] = Eigen::Quaterniond(-1, 0, 0, 0);
  p.rotations[1] = about(Eigen::Vector3d::UnitY(), 10);
  p.rotations[2] = Eigen::Quaterniond(-about(Eigen::Vector3d::UnitY(), 20).coeffs());
  const std::vector<double> q = continuous_quaternions(p);
  EXPECT_NEAR(q[0], 1.0, 1e-12);                          // w >= 0 at frame 0
  EXPECT_NEAR(q[4], std::cos(5 * kPi / 180), 1e-12);      // frame 1 kept
  EXPECT_NEAR(q[8], std::cos(10 * kPi / 180), 1e-12);     // frame 2 flipped back
  EXPECT_NEAR(q[10], std::sin(10 * kPi / 180), 1e-12);
}

TEST(MetricsTest, NpssOfIdenticalSeriesIsZero) {
  const std::vector<double> x = {0.1, 0.5, -0.2, 0.7, 0.3, 0.3, 0.9, -0.4};  // 4 frames, 2 channels
  const NpssTerms t = npss_terms(x, x, 2);
  EXPECT_GT(t.weight, 0.0);
  EXPECT_NEAR(t.value(), 0.0, 1e-15);
}

TEST(MetricsTest, NpssOfKnownPairs) {
  // T = 4, truth [1, 0, 0, 0]: Re DFT [1, 1, 1, 1], cumulative normalised power
  // [.25, .5, .75, 1]; prediction [1, 1, 1, 1]: Re DFT [4, 0, 0, 0], cumulative
  // [1, 1, 1, 1]. L1 distance .75 + .5 + .25 = 1.5, weight = truth power 4.
  NpssTerms t = npss_terms({1, 0, 0, 0}, {1, 1, 1, 1}, 1);
  EXPECT_NEAR(t.value(), 1.5, 1e-12);
  EXPECT_NEAR(t.weight, 4.0, 1e-12);

  // Two channels, T = 2 (frame-major). Channel 0: truth [1, 0] (power [1, 1],
  // total 2, cdf [.5, 1]), prediction [1, 1] (cdf [1, 1]): emd 0.5. Channel 1:
  // truth = prediction = [2, 2] (power [16, 0]): emd 0, weight 16.
  // NPSS = (2 * 0.5 + 16 * 0) / (2 + 16) = 1 / 18.
  t = npss_terms({1, 2, 0, 2}, {1, 2, 1, 2}, 2);
  EXPECT_NEAR(t.value(), 1.0 / 18.0, 1e-12);

  // A channel with zero truth power has no weight; a zero prediction has a zero
  // spectrum (cdf [0, 0] against [.5, 1]: emd 1.5).
  t = npss_terms({0, 1, 0, 0}, {3, 0, 4, 0}, 2);
  EXPECT_NEAR(t.weight, 2.0, 1e-12);
  EXPECT_NEAR(t.value(), 1.5, 1e-12);
  EXPECT_THROW(npss_terms({1, 2, 3}, {1, 2}, 1), InputError);
}

TEST(MetricsTest, MpjpeInCentimetres) {
  GlobalPose truth = zero_pose(2, 2), pred = zero_pose(2, 2);
  pos(pred, 1, 1) = Eigen::Vector3d(0.03, 0.0, 0.04);  // 5 cm on one joint of two
  EXPECT_NEAR(mpjpe_cm(truth, pred, {1}), 2.5, 1e-12);
  EXPECT_NEAR(mpjpe_cm(truth, pred, {0, 1}), 1.25, 1e-12);
  EXPECT_NEAR(mpjpe_cm(truth, pred, {0}), 0.0, 1e-12);
}

TEST(MetricsTest, ContactWeightFollowsNemf) {
  EXPECT_DOUBLE_EQ(contact_weight(0.0, 8.0), 1.0);
  EXPECT_DOUBLE_EQ(contact_weight(8.0, 8.0), 0.0);
  EXPECT_DOUBLE_EQ(contact_weight(20.0, 4.0), 0.0);   // clamped at 0
  EXPECT_DOUBLE_EQ(contact_weight(-8.0, 8.0), 1.0);   // 1.5 clamped at 1
  EXPECT_NEAR(contact_weight(4.0, 8.0), 2.0 - std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(contact_weight(2.0, 4.0), 2.0 - std::sqrt(2.0), 1e-15);
}

TEST(MetricsTest, FootSkatingOfKnownDisplacement) {
  // Joint 0 an ankle (8 cm), joint 1 a toe (4 cm), standing heights 10 and 4 cm.
  const std::vector<FootJoint> feet = {{0, 8.0}, {1, 4.0}};
  const std::vector<double> standing = {0.10, 0.04};
  GlobalPose p = zero_pose(3, 2);
  pos(p, 0, 0) = Eigen::Vector3d(0, 0.10, 0);
  pos(p, 1, 0) = Eigen::Vector3d(0.012, 0.10, 0.016);  // 2 cm at standing height: weight 1
  pos(p, 2, 0) = Eigen::Vector3d(0.012, 0.14, 0.046);  // 3 cm at +4 cm: weight 2 - sqrt 2
  pos(p, 0, 1) = Eigen::Vector3d(0, 0.04, 0);
  pos(p, 1, 1) = Eigen::Vector3d(0.05, 0.20, 0);        // 5 cm, 16 cm above: weight 0
  pos(p, 2, 1) = Eigen::Vector3d(0.05, 0.03, 0.01);     // 1 cm, 1 cm below: weight 1
  const SkatingTerms s = foot_skating(p, {0, 1, 2}, feet, standing);
  EXPECT_EQ(s.count, 4);  // frame 0 has no previous frame
  const double expected = 2.0 + 3.0 * (2.0 - std::sqrt(2.0)) + 0.0 + 1.0;
  EXPECT_NEAR(s.sum_cm, expected, 1e-9);
  EXPECT_NEAR(s.value(), expected / 4, 1e-9);
  EXPECT_NEAR(foot_skating(p, {1}, feet, standing).value(), 1.0, 1e-9);  // (2 + 0) / 2
}

TEST(MetricsTest, KnownFrameErrorOfOneRotatedRoot) {
  Motion truth = Motion::identity(two_joint_skeleton("Spine", {0.1, 0, 0}), 2, 30.0);
  Motion pred = truth;
  pred.rotation(1, 0) = about(Eigen::Vector3d::UnitY(), 30);
  const GlobalPose tp = forward_kinematics(truth), pp = forward_kinematics(pred);
  KnownFrameError e = known_frame_error(truth, tp, pred, pp, {0, 1});
  // The child, 10 cm from the root, moves along a chord of 30 degrees.
  const double chord = 2 * 10.0 * std::sin(15 * kPi / 180);
  EXPECT_EQ(e.count, 4);
  EXPECT_NEAR(e.rotation_max_deg, 30.0, 1e-9);
  EXPECT_NEAR(e.rotation_mean_deg(), 7.5, 1e-9);
  EXPECT_NEAR(e.position_max_cm, chord, 1e-9);
  EXPECT_NEAR(e.position_mean_cm(), chord / 4, 1e-9);
  e = known_frame_error(truth, tp, pred, pp, {0});
  EXPECT_EQ(e.position_max_cm, 0.0);
  EXPECT_EQ(e.rotation_max_deg, 0.0);
}

TEST(MetricsTest, EvalStatsOfStaticAndRisingClips) {
  const Skeleton s = two_joint_skeleton("Foot_L", {0, -0.9, 0.2});
  // Clip 1: 50 static frames at (5, 1, 7) facing +Z: one window; canonical root
  // (0, 1, 0), foot 0.2 m ahead (+X) and 0.1 m high; std floored.
  Clip a;
  a.name = "a.bvh";
  a.motion = Motion::identity(s, 50, 30.0);
  for (auto& r : a.motion.root_positions) r = Eigen::Vector3d(5, 1, 7);
  EvalStats stats = compute_eval_stats({a});
  EXPECT_EQ(stats.windows, 1);
  EXPECT_EQ(stats.clips, 1);
  const std::vector<double> mean = {0, 1, 0, 0.2, 0.1, 0};
  for (int d = 0; d < 6; ++d) {
    EXPECT_NEAR(stats.position_mean[d], mean[d], 1e-12) << d;
    EXPECT_EQ(stats.position_std[d], kMinStd) << d;
  }
  ASSERT_EQ(stats.feet.size(), 1u);
  EXPECT_EQ(stats.feet[0].joint, 1);
  EXPECT_NEAR(stats.standing_height[0], 0.1, 1e-12);

  // Clip 2: 60 frames rising 1 cm per frame (one 50-frame window at start 0):
  // foot heights 0.1 + 0.01 f, 5th percentile 0.1 + 0.01 * 0.05 * 59 = 0.1295;
  // the median over the two clips is 0.11475.
  Clip b;
  b.name = "b.bvh";
  b.motion = Motion::identity(s, 60, 30.0);
  for (int f = 0; f < 60; ++f) b.motion.root_positions[f] = Eigen::Vector3d(0, 1 + 0.01 * f, 0);
  stats = compute_eval_stats({a, b});
  EXPECT_EQ(stats.windows, 2);
  EXPECT_EQ(stats.clips, 2);
  EXPECT_NEAR(stats.standing_height[0], 0.11475, 1e-12);
  // Root height over the 100 samples: 50 at 1, 50 at 1 + 0.01 * (0..49).
  EXPECT_NEAR(stats.position_mean[1], 1.0 + 0.01 * 24.5 / 2, 1e-12);
  EXPECT_GT(stats.position_std[1], 0.01);

  Clip short_clip;
  short_clip.name = "c.bvh";
  short_clip.motion = Motion::identity(s, 49, 30.0);
  EXPECT_THROW(compute_eval_stats({short_clip}), InputError);
  EXPECT_THROW(compute_eval_stats({}), InputError);
}

TEST(MetricsTest, AccumulatorOfPerfectPredictionIsZero) {
  const Skeleton s = test::small_skeleton();
  Clip train;
  train.name = "t.bvh";
  train.motion = test::random_motion(s, 120, 30.0, 3);
  const EvalStats stats = compute_eval_stats({train});
  const Motion truth = canonicalise(test::random_motion(s, 40, 30.0, 4), 9);
  std::vector<int> evaluated, known;
  for (int f = 0; f < 40; ++f) (f >= 10 && f < 30 ? evaluated : known).push_back(f);

  MetricAccumulator acc(stats);
  acc.add(truth, truth, evaluated, known);
  MetricSummary m = acc.summary();
  EXPECT_EQ(m.windows, 1);
  EXPECT_NEAR(m.l2p, 0.0, 1e-12);
  EXPECT_NEAR(m.l2q, 0.0, 1e-12);
  EXPECT_NEAR(m.npss, 0.0, 1e-12);
  EXPECT_NEAR(m.mpjpe_cm, 0.0, 1e-12);
  EXPECT_NEAR(m.skating_cm, m.truth_skating_cm, 1e-12);
  EXPECT_NEAR(m.known.position_max_cm, 0.0, 1e-9);
  EXPECT_NEAR(m.known.rotation_max_deg, 0.0, 1e-4);

  // A prediction shifted by 3 cm up everywhere: MPJPE 3 cm; known frames too.
  Motion shifted = truth;
  for (auto& r : shifted.root_positions) r.y() += 0.03;
  MetricAccumulator acc2(stats);
  acc2.add(truth, shifted, evaluated, known);
  m = acc2.summary();
  EXPECT_NEAR(m.mpjpe_cm, 3.0, 1e-9);
  EXPECT_NEAR(m.known.position_max_cm, 3.0, 1e-9);
  EXPECT_NEAR(m.known.position_mean_cm(), 3.0, 1e-9);
  EXPECT_GT(m.l2p, 0.0);
  EXPECT_NEAR(m.l2q, 0.0, 1e-12);

  Motion wrong = Motion::identity(s, 39, 30.0);
  EXPECT_THROW(acc2.add(truth, wrong, evaluated, known), InputError);
  EXPECT_THROW(acc2.add(truth, truth, {}, known), InputError);
}

}  // namespace
}  // namespace mf::bench
