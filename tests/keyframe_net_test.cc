// KeyframeNet + RefineNet (prior/inbetween/keyframe_net.h) beyond what every
// transformer kind guarantees (transformer_kinds_test.cc): the trajectory is
// read, the keyframe selection keeps its spacings, the interpolation, and the
// Salient Poses scores of training/salient_poses.h.
#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <vector>

#include "prior/inbetween/keyframe_net.h"
#include "prior/motion/errors.h"
#include "prior/motion/rotations_torch.h"
#include "tasks/transformer/inbetweener_fill.h"
#include "tests/runtime_test_util.h"
#include "tests/test_util.h"
#include "training/salient_poses.h"

namespace mf {
namespace {

constexpr int kFrames = 40;

std::unique_ptr<InbetweenModel> tiny_model() {
  at::manual_seed(3);
  auto model = make_keyframe_net({{"width", 32}, {"layers", 1}, {"heads", 2}, {"ffn", 32}, {"window", 64},
                                  {"min_spacing", 3}, {"max_spacing", 8}},
                                 test::tiny_rig());
  model->train(false);
  return model;
}

// 10 context frames, a 29-frame gap, the target: real poses of a random motion.
InbetweenBatch gap_window(const InbetweenModel& model, at::Tensor* truth) {
  Motion m = test::random_motion(model.rig().skeleton, kFrames, 30.0, 11);
  WindowTensors w = window_tensors(m, 0, kFrames, model.rig(), 0);
  *truth = pose_features(w.local_rotations, w.root_positions);
  const int64_t J = model.rig().num_joints();
  InbetweenBatch b;
  b.known = at::zeros({1, kFrames, J + 1});
  b.known[0].narrow(0, 0, 10).fill_(1.0);
  b.known[0][kFrames - 1].fill_(1.0);
  b.valid = at::ones({1, kFrames});
  b.pose = *truth * known_channel_mask(b.known, static_cast<int>(J));
  return b;
}

TEST(KeyframeNet, TheTrajectoryIsRead) {
  auto model = tiny_model();
  at::NoGradGuard no_grad;
  at::Tensor truth;
  InbetweenBatch b = gap_window(*model, &truth);
  InbetweenBatch explicit_batch = b;
  explicit_batch.trajectory = interpolated_trajectory(b.pose, b.known, model->rig());
  // The default trajectory: facing vectors of unit length, ground positions through the known ones.
  EXPECT_TRUE(at::allclose(explicit_batch.trajectory.narrow(-1, 2, 2).norm(2, -1), at::ones({1, kFrames}), 1e-4));
  const int64_t D = model->pose_size();
  EXPECT_NEAR(explicit_batch.trajectory[0][kFrames - 1][0].item<float>(), b.pose[0][kFrames - 1][D - 3].item<float>(), 1e-5);
  // A given trajectory is followed at the keyframes the interpolation runs through.
  InbetweenOutput given = model->forward(explicit_batch);
  at::Tensor picked = given.keyframes[0] * (1 - b.known[0].select(-1, 0));
  ASSERT_GT(picked.sum().item<float>(), 0.0f);  // a 29-frame gap, keyframes at most 8 apart
  at::Tensor dx = (given.stages[0][0].select(-1, D - 3) - explicit_batch.trajectory[0].select(-1, 0)).abs() * picked;
  EXPECT_LT(dx.max().item<float>(), 1e-4);
  // Another path changes the answer inside the gap.
  InbetweenBatch moved = explicit_batch;
  moved.trajectory = explicit_batch.trajectory.clone();
  moved.trajectory[0].narrow(0, 15, 10).select(-1, 0).add_(1.0);
  at::Tensor out = model->forward(moved).stages.back();
  EXPECT_GT((out - given.stages.back()).abs().max().item<float>(), 1e-4);
  moved.trajectory = at::zeros({1, kFrames, 3});
  EXPECT_THROW(model->forward(moved), InputError);
}

// Spacings between consecutive interpolation points (anchors and picks) of row b.
std::vector<int> spacings(const at::Tensor& anchors, const at::Tensor& picked, int64_t b) {
  std::vector<int> points, out;
  for (int64_t t = 0; t < anchors.size(1); ++t)
    if (anchors[b][t].item<bool>() || picked[b][t].item<bool>()) points.push_back(static_cast<int>(t));
  for (size_t i = 1; i < points.size(); ++i) out.push_back(points[i] - points[i - 1]);
  return out;
}

TEST(KeyframeNet, SelectionRespectsMinAndMaxSpacing) {
  const int T = 150, lo = 5, hi = 30;
  at::manual_seed(1);
  // Rows: random scores, all low (only forced picks), all high (as many as min spacing allows).
  at::Tensor logits = at::stack({at::randn({T}) * 3, at::full({T}, -1.0), at::full({T}, 1.0)});
  at::Tensor anchors = at::zeros({3, T}, at::kBool);
  anchors.narrow(1, 0, 10).fill_(true);
  anchors.select(1, T - 1).fill_(true);
  at::Tensor valid = at::ones({3, T});
  at::Tensor picked = select_keyframes(logits, anchors, valid, lo, hi);
  EXPECT_FALSE((picked & anchors).any().item<bool>());
  for (int64_t b = 0; b < 3; ++b) {
    std::vector<int> s = spacings(anchors, picked, b);
    for (size_t i = 9; i < s.size(); ++i) {  // after the 10 context frames
      EXPECT_GE(s[i], lo) << "row " << b;
      EXPECT_LE(s[i], hi) << "row " << b;
    }
  }
  // Equal low scores: only the forced picks, max_spacing apart (ties go to the later frame).
  auto frames_of = [&](int64_t b) {
    std::vector<int> f;
    for (int t = 0; t < T; ++t)
      if (picked[b][t].item<bool>()) f.push_back(t);
    return f;
  };
  EXPECT_EQ(frames_of(1), (std::vector<int>{39, 69, 99, 129}));
  // Equal high scores: the same, then one optional pick as far as min_spacing allows.
  EXPECT_EQ(frames_of(2), (std::vector<int>{39, 69, 99, 129, 144}));
  // Padding is never picked and ends the row like a target.
  valid[0].narrow(0, 100, T - 100).zero_();
  at::Tensor padded = select_keyframes(logits, anchors, valid, lo, hi);
  EXPECT_FALSE(padded[0].narrow(0, 100 - lo + 1, T - 100 + lo - 1).any().item<bool>());
  EXPECT_THROW(select_keyframes(logits, anchors, valid, 5, 9), InputError);
  EXPECT_THROW(select_keyframes(logits, anchors, valid, 0, 9), InputError);
}

TEST(KeyframeNet, InterpolationIsExactAtKeysSlerpAndLerpBetween) {
  const int J = 1, T = 5;
  // Joint 0 rotates about y from 0 to 90 degrees between frames 0 and 4; the root moves 4 m.
  auto yaw = [](double a) {
    return at::tensor({std::cos(a), 0.0, std::sin(a), 0.0, 1.0, 0.0, -std::sin(a), 0.0, std::cos(a)}, at::kFloat)
        .view({3, 3});
  };
  at::Tensor poses = at::zeros({1, T, 6 * J + 3});
  poses[0][0] = at::cat({torch_rot::matrix_to_sixd(yaw(0.0)).flatten(), at::zeros({3})});
  poses[0][4] = at::cat({torch_rot::matrix_to_sixd(yaw(M_PI / 2)).flatten(), at::tensor({4.f, 0.f, 0.f})});
  at::Tensor keys = at::zeros({1, T}, at::kBool);
  keys[0][0] = true;
  keys[0][4] = true;
  at::Tensor out = interpolate_keyframes(poses, keys, J);
  EXPECT_TRUE(at::allclose(out[0][0], poses[0][0], 1e-5, 1e-5));
  EXPECT_TRUE(at::allclose(out[0][4], poses[0][4], 1e-5, 1e-5));
  EXPECT_TRUE(at::allclose(out[0][2].narrow(0, 0, 6), torch_rot::matrix_to_sixd(yaw(M_PI / 4)).flatten(), 1e-5, 1e-5));
  EXPECT_NEAR(out[0][1][6].item<float>(), 1.0f, 1e-5);
}

// One joint on a path with corners at frames 7 and 15 (straight in between).
at::Tensor cornered_path() {
  const int n = 21;
  at::Tensor p = at::zeros({n, 1, 3});
  for (int t = 0; t < n; ++t) {
    float x = t <= 7 ? t : 7.0f, z = t <= 7 ? 0.0f : (t <= 15 ? t - 7.0f : 8.0f);
    if (t > 15) x = 7.0f - (t - 15);
    p[t][0][0] = x * 0.1f;
    p[t][0][2] = z * 0.1f;
  }
  return p;
}

TEST(SalientPoses, CornersAreTheOptimalKeyframes) {
  at::Tensor p = cornered_path();
  auto cost = training::salient_span_costs(p);
  EXPECT_NEAR(cost[0][7], 0.0, 1e-6);  // straight spans cost nothing (float inputs)
  EXPECT_NEAR(cost[7][15], 0.0, 1e-6);
  EXPECT_GT(cost[0][15], 0.3);  // across a corner: the corner's distance to the chord
  auto sets = training::salient_keyframe_sets(p, 5);
  ASSERT_EQ(sets.size(), 4u);
  EXPECT_EQ(sets[0], (std::vector<int>{0, 20}));
  EXPECT_EQ(sets[1], (std::vector<int>{0, 7, 20}));      // the larger corner
  EXPECT_EQ(sets[2], (std::vector<int>{0, 7, 15, 20}));  // zero cost, unique
  EXPECT_EQ(sets[3].size(), 5u);
  EXPECT_EQ(sets[3].front(), 0);
  EXPECT_EQ(sets[3].back(), 20);
  // Scores: the ends 1, the corners above every other frame.
  at::Tensor s = training::salient_scores(p, 5);
  EXPECT_FLOAT_EQ(s[0].item<float>(), 1.0f);
  EXPECT_FLOAT_EQ(s[20].item<float>(), 1.0f);
  for (int t = 1; t < 20; ++t) {
    if (t == 7 || t == 15) continue;
    EXPECT_LT(s[t].item<float>(), std::min(s[7].item<float>(), s[15].item<float>())) << t;
  }
  EXPECT_THROW(training::salient_scores(p, 0), InputError);
  EXPECT_THROW(training::salient_keyframe_sets(p.narrow(0, 0, 1), 3), InputError);
}

TEST(KeyframeNetGlue, CanonicalTrajectoryUndoesTheGroundTransform) {
  GroundTransform g;
  g.yaw = M_PI / 2;
  g.x = 1.0;
  g.z = 2.0;
  // world = R_y(yaw) canonical + (x, 0, z): canonical (-1, 0) facing -x is world (1, 3) facing +z.
  runtime::MatrixRXf world(1, 4);
  world << 1.0f, 3.0f, 0.0f, 1.0f;
  const runtime::MatrixRXf c = canonical_trajectory(world, g);
  runtime::MatrixRXf expected(1, 4);
  expected << -1.0f, 0.0f, -1.0f, 0.0f;
  EXPECT_TRUE(c.isApprox(expected, 1e-5)) << c;
  EXPECT_THROW(canonical_trajectory(runtime::MatrixRXf::Zero(1, 3), g), InputError);
}

TEST(KeyframeNetGlue, ConstrainedTrajectoryKeysWinRowsFillTheRest) {
  const RigInfo rig = test::tiny_rig();
  Motion m = test::random_motion(rig.skeleton, 21, 30.0, 5);
  MotionConstraints c = MotionConstraints::full_pose({0, 20});
  EXPECT_EQ(constrained_trajectory(m, c, rig).rows(), 0);  // no rows: the model interpolates itself
  c.trajectory = {{0, 50.0, 50.0, 1.0, 0.0}, {10, 3.0, -1.0, 0.0, 2.0}};
  const runtime::MatrixRXf t = constrained_trajectory(m, c, rig);
  ASSERT_EQ(t.rows(), 21);
  ASSERT_EQ(t.cols(), 4);
  EXPECT_NEAR(t(0, 0), m.root_positions[0].x(), 1e-5);  // the key wins over the row
  EXPECT_NEAR(t(20, 1), m.root_positions[20].z(), 1e-5);
  EXPECT_NEAR(t(10, 0), 3.0, 1e-5);
  EXPECT_NEAR(t(10, 3), 1.0, 1e-5);  // facing normalised
  EXPECT_NEAR(t(5, 0), 0.5 * (m.root_positions[0].x() + 3.0), 1e-4);  // interpolated
}

TEST(KeyframeNetGlue, FillReadsTheTrajectory) {
  auto model = tiny_model();
  Motion m = test::random_motion(model->rig().skeleton, kFrames, 30.0, 8);
  std::vector<int> known;
  for (int f = 0; f < 10; ++f) known.push_back(f);
  known.push_back(kFrames - 1);
  MotionConstraints c = MotionConstraints::full_pose(known);
  const auto net = test::runtime_of(*model);
  const Motion plain = inbetweener_fill(*net, -1, m, c, LongGapPolicy::Throw);
  for (int f = 10; f < kFrames - 1; ++f) c.trajectory.push_back({f, 0.1 * f, 2.0, 1.0, 0.0});
  const Motion along = inbetweener_fill(*net, -1, m, c, LongGapPolicy::Throw);
  double moved = 0.0;
  for (int f = 10; f < kFrames - 1; ++f) moved = std::max(moved, (along.root_positions[f] - plain.root_positions[f]).norm());
  EXPECT_GT(moved, 1e-4);
  for (int f : known) EXPECT_TRUE(along.root_positions[f].isApprox(m.root_positions[f])) << f;
}

}  // namespace
}  // namespace mf
