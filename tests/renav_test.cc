// Re-navigation (tasks/renav/renav.h) on tiny random models: path CSV parsing and
// its errors, polyline resampling by arc length, tangents, the energy (lower for
// a motion that follows the path, gradients reaching the latent codes only),
// the solve (energy decrease, cancellation, output length and frame rate,
// windows, determinism) and the task entry point's errors.
#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <memory>
#include <string>

#include "prior/model/nemf.h"
#include "prior/model/representation.h"
#include "prior/motion/errors.h"
#include "tasks/reference/renav_energy.h"
#include "tasks/renav/renav.h"
#include "tests/runtime_test_util.h"
#include "tests/test_util.h"

namespace mf {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::shared_ptr<NemfModel> tiny_model() {
  at::manual_seed(5);
  auto model = std::make_shared<NemfModel>(test::tiny_nemf_config(), test::tiny_rig());
  model->set_requires_grad(false);
  return model;
}

// A test prior on the Eigen runtime, as the tasks take it.
runtime::NemfRuntime on_runtime(const NemfModel& model) { return test::runtime_of(model); }

// The message of the InputError `fn` throws ("" if none).
template <class Fn>
std::string input_error(Fn&& fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::vector<Eigen::Vector2d> root_path(const Motion& m) {
  std::vector<Eigen::Vector2d> p;
  for (const Eigen::Vector3d& r : m.root_positions) p.emplace_back(r.x(), r.z());
  return p;
}

std::vector<Eigen::Vector2d> line_path(int frames, double step) {
  std::vector<Eigen::Vector2d> p;
  for (int f = 0; f < frames; ++f) p.emplace_back(0.3 * std::sin(0.2 * f), step * f);
  return p;
}

// ---------------------------------------------------------------- paths

TEST(RenavPath, ParsesCsvWithHeaderCommentsAndBlankLines) {
  const auto p = parse_path_csv("x,z\n# a comment\n0,0\n\n  1.5 , -2\r\n   # indented comment\n+3,4e-1\n", "p.csv");
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p[0], Eigen::Vector2d(0, 0));
  EXPECT_EQ(p[1], Eigen::Vector2d(1.5, -2));
  EXPECT_EQ(p[2], Eigen::Vector2d(3, 0.4));
  // Without a header, without a final newline; a header-like line is only a header first.
  EXPECT_EQ(parse_path_csv("1,2\n3,4", "p.csv").size(), 2u);
  EXPECT_EQ(parse_path_csv(" X , Z \n1,2\n3,4\n", "p.csv").size(), 2u);
}

TEST(RenavPath, CsvErrorsNameTheSourceAndLine) {
  auto error = [](const std::string& text) { return input_error([&] { parse_path_csv(text, "path.csv"); }); };
  EXPECT_NE(error("").find("path.csv: a path needs at least two points"), std::string::npos) << error("");
  EXPECT_NE(error("x,z\n1,2\n").find("at least two points"), std::string::npos);
  EXPECT_NE(error("0,0\n1,nan\n").find("path.csv:2: non-finite"), std::string::npos) << error("0,0\n1,nan\n");
  EXPECT_NE(error("0,0\n# c\ninf,1\n").find("path.csv:3: non-finite"), std::string::npos);
  EXPECT_NE(error("0,0\n1;2\n").find("path.csv:2: expected two comma-separated numbers"), std::string::npos);
  EXPECT_NE(error("0,0\n1,2,3\n").find("path.csv:2:"), std::string::npos);
  EXPECT_NE(error("0,0\n1,\n").find("path.csv:2:"), std::string::npos);
  EXPECT_NE(error("0,0\nabc,1\n").find("path.csv:2:"), std::string::npos);
  EXPECT_NE(error("0,0\n1,2 m\n").find("path.csv:2:"), std::string::npos);
  EXPECT_NE(error("0,0\nx,z\n1,1\n").find("path.csv:2:"), std::string::npos);  // a header after data
  EXPECT_NE(input_error([] { read_path_csv("/nonexistent/dir/p.csv"); }).find("cannot open"), std::string::npos);
}

TEST(RenavPath, Validation) {
  EXPECT_NE(input_error([] { validate_path({{0, 0}}); }).find("at least two points"), std::string::npos);
  EXPECT_NE(input_error([] { validate_path({{0, 0}, {0, 0}, {0, 0}}); }).find("zero length"), std::string::npos);
  EXPECT_NE(input_error([] { validate_path({{0, 0}, {NAN, 1}}); }).find("point 1 is not finite"), std::string::npos);
  EXPECT_EQ(input_error([] { validate_path({{0, 0}, {0, 0.01}}); }), "");
}

TEST(RenavPath, PolylineResampledByArcLength) {
  // An L of length 3 + 4 = 7 m: 8 frames are 1 m apart, around the corner.
  const std::vector<Eigen::Vector2d> l = {{0, 0}, {3, 0}, {3, 4}};
  const auto p = resample_polyline(l, 8);
  const std::vector<Eigen::Vector2d> want = {{0, 0}, {1, 0}, {2, 0}, {3, 0}, {3, 1}, {3, 2}, {3, 3}, {3, 4}};
  ASSERT_EQ(p.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) EXPECT_LT((p[i] - want[i]).norm(), 1e-12) << i;
  // 3 frames: the middle one at 3.5 m, half a metre past the corner; a repeated vertex changes nothing.
  const auto q = resample_polyline({{0, 0}, {3, 0}, {3, 0}, {3, 4}}, 3);
  EXPECT_LT((q[1] - Eigen::Vector2d(3, 0.5)).norm(), 1e-12);
  EXPECT_EQ(q[2], Eigen::Vector2d(3, 4));
  // Frame count at a walking speed: 7 m at 1.4 m/s and 30 fps = 150 steps.
  EXPECT_EQ(polyline_frame_count(l, 1.4, 30.0), 151);
  EXPECT_EQ(polyline_frame_count({{0, 0}, {0, 0.001}}, 1.0, 30.0), 2);
  EXPECT_NE(input_error([&] { polyline_frame_count(l, 0.001, 30.0); }).find("barely moves"), std::string::npos);
  EXPECT_NE(input_error([&] { resample_polyline(l, 1); }), "");
  EXPECT_NE(input_error([&] { resample_polyline({{1, 1}, {1, 1}}, 5); }).find("zero length"), std::string::npos);
  EXPECT_DOUBLE_EQ(path_length(l), 7.0);
}

TEST(RenavPath, GroundSpeedAndTangents) {
  Motion m = Motion::identity(test::small_skeleton(), 31, 30.0);
  for (int f = 0; f < 31; ++f) m.root_positions[f] = Eigen::Vector3d(0.03 * f, 0.9 + 0.1 * f, -0.04 * f);
  EXPECT_NEAR(mean_ground_speed(m), 1.5, 1e-12);  // 5 cm per frame on the ground; height ignored

  // Along +X: yaw +90 degrees; a pause in the middle holds the nearest tangent.
  std::vector<Eigen::Vector2d> p;
  for (int f = 0; f < 10; ++f) p.emplace_back(0.1 * f, 0.0);
  for (int f = 0; f < 10; ++f) p.emplace_back(0.9, 0.0);
  for (int f = 1; f <= 10; ++f) p.emplace_back(0.9, 0.1 * f);
  const std::vector<double> yaw = tangent_yaws(p);
  EXPECT_NEAR(yaw[0], kPi / 2, 1e-12);
  EXPECT_NEAR(yaw[12], kPi / 2, 1e-12);  // paused, nearer to the +X part
  EXPECT_NEAR(yaw[17], 0.0, 1e-12);      // paused, nearer to the +Z part
  EXPECT_NEAR(yaw[29], 0.0, 1e-12);
  // A path that never moves takes the fallback.
  const std::vector<double> still = tangent_yaws({{1, 1}, {1, 1}, {1, 1}}, {0.1, 0.2, 0.3});
  EXPECT_DOUBLE_EQ(still[1], 0.2);
}

TEST(RenavPath, ReferencePaceIsTheSpeedRatioWithinLimits) {
  // A reference walking v m/s along +Z for 61 frames at 30 fps.
  auto walk = [](double v) {
    Motion m = Motion::identity(test::small_skeleton(), 61, 30.0);
    for (int f = 0; f < 61; ++f) m.root_positions[f] = Eigen::Vector3d(0.0, 0.9, v * f / 30.0);
    return m;
  };
  std::vector<Eigen::Vector2d> p;
  for (int f = 0; f <= 30; ++f) p.emplace_back(0.03 * f, -0.04 * f);  // 1.5 m in 1 s
  EXPECT_NEAR(reference_pace(walk(1.0), p, 30.0), 1.5, 1e-9);
  EXPECT_NEAR(reference_pace(walk(2.0), p, 30.0), 0.75, 1e-9);
  EXPECT_NEAR(reference_pace(walk(1.0), p, 60.0), 2.0, 1e-9);  // the same points twice as fast: 3 m/s, clamped
  EXPECT_EQ(reference_pace(walk(1.46), p, 30.0), 1.0);          // within 5 %: played as it is
  EXPECT_EQ(reference_pace(walk(1.54), p, 30.0), 1.0);
  EXPECT_EQ(reference_pace(walk(0.3), p, 30.0), kMaxPace);      // 5x faster: at most 2x
  EXPECT_EQ(reference_pace(walk(30.0), p, 30.0), kMinPace);
  EXPECT_EQ(reference_pace(walk(0.01), p, 30.0), 1.0);          // a clip in place has no pace to match
  EXPECT_EQ(reference_pace(walk(1.0), {{0, 0}}, 30.0), 1.0);
  // The mean speeds decide, not where the reference is fast or slow: one that
  // stands for its first 15 frames, then walks 2 m/s, averages the path's 1.5.
  Motion pause = walk(0.0);
  for (int f = 15; f < 61; ++f) pause.root_positions[f].z() = 2.0 * (f - 15) / 30.0;
  EXPECT_EQ(reference_pace(pause, p, 30.0), 1.0);
  std::vector<Eigen::Vector2d> slow_far;
  for (int f = 0; f <= 300; ++f) slow_far.emplace_back(0.0, 0.05 * f);  // 15 m in 10 s
  EXPECT_NEAR(reference_pace(walk(1.0), slow_far, 30.0), 1.5, 1e-9);
}

// ---------------------------------------------------------------- the energy

TEST(RenavEnergyTest, LowerForAMotionThatFollowsThePath) {
  auto model = tiny_model();
  const RigInfo& rig = model->rig();
  const Motion ref = test::random_motion(rig.skeleton, 32, 30.0, 7);
  // The target is the reference's own root path: the reference itself follows
  // it in its own style (joints and heading divergences 0).
  const std::vector<Eigen::Vector2d> path = root_path(ref);
  const RenavWindow w = make_renav_window(on_runtime(*model), ref, 0, 32, path, 0, 32);
  const RenavWeights weights;
  // The energy of a world motion, given in the window's canonical frame.
  auto energy = [&](const Motion& m) {
    const Eigen::Matrix3d unturn = Eigen::AngleAxisd(-w.transform.yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
    const int J = rig.num_joints();
    at::Tensor rot = at::empty({1, 32, J, 3, 3});
    at::Tensor pos = at::empty({1, 32, 3});
    for (int f = 0; f < 32; ++f) {
      for (int j = 0; j < J; ++j) {
        Eigen::Matrix3d r = m.rotation(f, j).normalized().toRotationMatrix();
        if (j == 0) r = unturn * r;
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) rot[0][f][j][a][b] = static_cast<float>(r(a, b));
      }
      const Eigen::Vector3d& r = m.root_positions[f];
      const Eigen::Vector3d c = unturn * Eigen::Vector3d(r.x() - w.transform.x, r.y(), r.z() - w.transform.z);
      for (int a = 0; a < 3; ++a) pos[0][f][a] = static_cast<float>(c[a]);
    }
    return renav_motion_energy(rig, 30.0, w, weights, rot, pos, {}).total.item<double>();
  };
  const double follows = energy(ref);
  Motion sideways = ref;  // same motion, 40 cm to the side
  for (auto& r : sideways.root_positions) r.x() += 0.4;
  Motion other = test::random_motion(rig.skeleton, 32, 30.0, 8);  // another motion moved onto the path
  for (int f = 0; f < 32; ++f) {
    other.root_positions[f].x() = path[f].x();
    other.root_positions[f].z() = path[f].y();
  }
  const double off_path = energy(sideways), other_style = energy(other);
  EXPECT_LT(follows, 0.01);  // the smoothed L1's floor is 1e-3
  EXPECT_GT(off_path, follows + 0.15);
  EXPECT_GT(other_style, follows + 0.01);
}

TEST(RenavEnergyTest, GradientsReachTheCodesOnly) {
  auto model = tiny_model();
  const RigInfo& rig = model->rig();
  const Motion ref = test::random_motion(rig.skeleton, 40, 30.0, 9);
  const RenavWindow w = make_renav_window(on_runtime(*model), ref, 0, 32, line_path(40, 0.04), 4, 32);
  RenavWeights weights;
  weights.foot_skating = 1.0;
  at::manual_seed(3);
  at::Tensor z_l = at::randn({1, model->config().zl}).requires_grad_(true);
  at::Tensor z_g = at::randn({1, model->config().zg}).requires_grad_(true);
  const RenavEnergy e = evaluate_renav_energy(*model, w, weights, z_l, z_g);
  ASSERT_EQ(e.terms.size(), 4u);  // path, joints, heading, foot_skating (no previous window)
  EXPECT_EQ(e.terms[0].first, "path");
  EXPECT_EQ(e.terms[3].first, "foot_skating");
  e.total.backward();
  ASSERT_TRUE(z_l.grad().defined());
  ASSERT_TRUE(z_g.grad().defined());
  EXPECT_TRUE(at::isfinite(z_l.grad()).all().item<bool>());
  EXPECT_GT(z_l.grad().abs().sum().item<double>(), 0.0);
  EXPECT_GT(z_g.grad().abs().sum().item<double>(), 0.0);
  for (const auto& p : model->named_parameters()) {
    EXPECT_FALSE(p.second.requires_grad()) << p.first;
    EXPECT_FALSE(p.second.grad().defined()) << p.first;
  }
}

// Re-navigation reads the steering GMP where the model has one: editing the
// default GMP changes nothing, editing the steering GMP changes the energy.
TEST(RenavEnergyTest, UsesTheSteeringGmp) {
  NemfConfig c = test::tiny_nemf_config();
  c.steering_gmp = 1;
  at::manual_seed(5);
  NemfModel model(c, test::tiny_rig());
  model.set_requires_grad(false);
  const Motion ref = test::random_motion(model.rig().skeleton, 40, 30.0, 9);
  const RenavWindow w = make_renav_window(on_runtime(model), ref, 0, 32, line_path(40, 0.04), 4, 32);
  RenavWeights weights;
  weights.foot_skating = 1.0;
  at::manual_seed(3);
  const at::Tensor z_l = at::randn({1, c.zl}), z_g = at::randn({1, c.zg});
  auto energy = [&] { return evaluate_renav_energy(model, w, weights, z_l, z_g).total.item<double>(); };
  auto root = [&] { return decode_renav_window(model, w, z_l, z_g).root_positions; };
  const double e0 = energy();
  const runtime::MatrixRXf r0 = root();
  at::NoGradGuard no_grad;
  auto scale = [&](const std::string& prefix) {
    for (auto& [name, value] : model.named_parameters())
      if (name.rfind(prefix, 0) == 0) value.mul_(3.0);
  };
  scale("gmp.");
  EXPECT_EQ(energy(), e0);
  EXPECT_EQ(root(), r0);
  scale("steering_gmp.");
  EXPECT_NE(energy(), e0);
  EXPECT_GT((root() - r0).cwiseAbs().maxCoeff(), 1e-4f);
}

TEST(RenavEnergyTest, WindowStartsOnThePathWithTheReferencesFacing) {
  auto model = tiny_model();
  const RigInfo& rig = model->rig();
  const Motion ref = test::random_motion(rig.skeleton, 32, 30.0, 10);
  const auto path = line_path(32, 0.05);
  const RenavWindow w = make_renav_window(on_runtime(*model), ref, 0, 32, path, 0, 32);
  EXPECT_DOUBLE_EQ(w.transform.x, path[0].x());
  EXPECT_DOUBLE_EQ(w.transform.z, path[0].y());
  EXPECT_NEAR(w.target_xz(0, 0), 0.0, 1e-6);
  EXPECT_NEAR(w.target_xz(0, 1), 0.0, 1e-6);
  // The turned reference canonicalises at frame 0 to the window's frame.
  const GroundTransform g = canonical_transform(w.turned_segment, 0, rig);
  EXPECT_NEAR(std::remainder(g.yaw - w.transform.yaw, 2 * kPi), 0.0, 1e-9);
  EXPECT_NEAR(g.x, w.transform.x, 1e-9);
  EXPECT_NEAR(g.z, w.transform.z, 1e-9);
  // ...and its root follows the target path.
  for (int f = 0; f < 32; ++f) {
    EXPECT_NEAR(w.turned_segment.root_positions[f].x(), path[f].x(), 1e-9);
    EXPECT_NEAR(w.turned_segment.root_positions[f].z(), path[f].y(), 1e-9);
  }
}

// ---------------------------------------------------------------- the solve

RenavOptions quick(LatentOptimizer solver, int iterations) {
  RenavOptions o = default_renav_options(solver);
  o.max_iterations = iterations;
  return o;
}

TEST(Renavigate, DecreasesTheEnergyAndHasThePathsLength) {
  auto model = tiny_model();
  const Motion ref = test::random_motion(model->rig().skeleton, 40, 30.0, 11);
  const auto path = line_path(50, 0.04);  // 50 frames: two windows of 32
  RenavReport report;
  const Motion out = renavigate(on_runtime(*model), ref, path, 30.0, quick(LatentOptimizer::Lbfgs, 25), {}, &report);
  EXPECT_EQ(out.num_frames(), 50);
  EXPECT_EQ(out.fps, 30.0);
  EXPECT_TRUE(out.skeleton.same_as(ref.skeleton));
  EXPECT_NO_THROW(out.validate());
  ASSERT_EQ(report.windows.size(), 2u);
  EXPECT_EQ(report.windows[0].begin, 0);
  EXPECT_EQ(report.windows[1].begin, 18);
  EXPECT_EQ(report.windows[1].length, 32);
  for (const RenavWindowSummary& w : report.windows) {
    EXPECT_LT(w.final_energy, w.initial_energy);
    EXPECT_GT(w.iterations, 0);
    EXPECT_EQ(w.init_energies.size(), 3u);
  }
  EXPECT_EQ(report.windows[1].final_terms.back().first, "continuity");
  // The output starts exactly on the path.
  EXPECT_NEAR(out.root_positions[0].x(), path[0].x(), 1e-6);
  EXPECT_NEAR(out.root_positions[0].z(), path[0].y(), 1e-6);
  EXPECT_GT(report.path_error_mean_cm, 0.0);
  EXPECT_EQ(report.pace, reference_pace(ref, path, 30.0));
}

TEST(Renavigate, PlaysTheReferenceAtThePathsPace) {
  auto model = tiny_model();
  Motion ref = test::random_motion(model->rig().skeleton, 40, 30.0, 11);
  for (int f = 0; f < 40; ++f) ref.root_positions[f] = Eigen::Vector3d(0.0, 0.9, 0.02 * f);  // 0.6 m/s
  const auto path = line_path(20, 0.04);  // 1.2 m/s
  RenavOptions o = quick(LatentOptimizer::Lbfgs, 5);
  RenavReport paced, as_is;
  const Motion a = renavigate(on_runtime(*model), ref, path, 30.0, o, {}, &paced);
  o.match_pace = false;
  const Motion b = renavigate(on_runtime(*model), ref, path, 30.0, o, {}, &as_is);
  EXPECT_NEAR(paced.pace, 2.0, 1e-9);
  EXPECT_EQ(as_is.pace, 1.0);
  EXPECT_EQ(a.num_frames(), 20);
  EXPECT_EQ(b.num_frames(), 20);
  // The 20-frame window is compared with the whole reference played twice as
  // fast (frames 0-38 of 0-39), not with its first 20 frames.
  ASSERT_EQ(paced.windows.size(), 1u);
  EXPECT_DOUBLE_EQ(paced.windows[0].reference_from, 0.0);
  EXPECT_NEAR(paced.windows[0].reference_to, 38.0 / 30.0, 1e-9);
  EXPECT_NEAR(as_is.windows[0].reference_to, 19.0 / 30.0, 1e-9);
  // Two frames cannot be played twice as fast: such a reference keeps its pace.
  RenavReport two;
  o.match_pace = true;
  const Motion c = renavigate(on_runtime(*model), ref.slice(0, 2), path, 30.0, o, {}, &two);
  EXPECT_EQ(c.num_frames(), 20);
  EXPECT_EQ(two.pace, 1.0);
}

TEST(Renavigate, AdamAndOtherFrameRates) {
  auto model = tiny_model();
  const Motion ref = test::random_motion(model->rig().skeleton, 30, 30.0, 12);
  // 45 points at 60 fps: 22 model frames (one window), resampled back to 45 frames at 60 fps.
  RenavReport report;
  const Motion out = renavigate(on_runtime(*model), ref, line_path(45, 0.02), 60.0, quick(LatentOptimizer::Adam, 30), {}, &report);
  EXPECT_EQ(out.num_frames(), 45);
  EXPECT_EQ(out.fps, 60.0);
  ASSERT_EQ(report.windows.size(), 1u);
  EXPECT_EQ(report.windows[0].length, 23);
  EXPECT_LE(report.windows[0].final_energy, report.windows[0].initial_energy);
  // A reference at another frame rate is resampled to the model's.
  Motion ref60 = test::random_motion(model->rig().skeleton, 40, 60.0, 13);
  const Motion out2 = renavigate(on_runtime(*model), ref60, line_path(20, 0.04), 30.0, quick(LatentOptimizer::Lbfgs, 5));
  EXPECT_EQ(out2.num_frames(), 20);
}

TEST(Renavigate, RespectsCancelAndProgress) {
  auto model = tiny_model();
  const Motion ref = test::random_motion(model->rig().skeleton, 32, 30.0, 14);
  const auto path = line_path(32, 0.04);
  std::atomic<int> cancel{1};
  TaskContext ctx;
  ctx.cancel = &cancel;
  EXPECT_THROW(renavigate(on_runtime(*model), ref, path, 30.0, quick(LatentOptimizer::Lbfgs, 50), ctx), CancelledError);
  int calls = 0;
  TaskContext ctx2;
  ctx2.progress = [&](const TaskProgress& p) {
    EXPECT_EQ(p.max_iterations, 50);
    return ++calls < 4;
  };
  EXPECT_THROW(renavigate(on_runtime(*model), ref, path, 30.0, quick(LatentOptimizer::Lbfgs, 50), ctx2), CancelledError);
  EXPECT_EQ(calls, 4);
  calls = 0;
  EXPECT_THROW(renavigate(on_runtime(*model), ref, path, 30.0, quick(LatentOptimizer::Adam, 50), ctx2), CancelledError);
  EXPECT_EQ(calls, 4);
}

TEST(Renavigate, Deterministic) {
  auto model = tiny_model();
  const Motion ref = test::random_motion(model->rig().skeleton, 32, 30.0, 15);
  const auto path = line_path(40, 0.03);
  TaskContext ctx;
  ctx.seed = 7;
  const Motion a = renavigate(on_runtime(*model), ref, path, 30.0, quick(LatentOptimizer::Lbfgs, 10), ctx);
  const Motion b = renavigate(on_runtime(*model), ref, path, 30.0, quick(LatentOptimizer::Lbfgs, 10), ctx);
  for (int f = 0; f < a.num_frames(); ++f) {
    ASSERT_EQ(a.root_positions[f], b.root_positions[f]) << f;
    for (int j = 0; j < a.num_joints(); ++j) ASSERT_EQ(a.rotation(f, j).coeffs(), b.rotation(f, j).coeffs());
  }
}

// Foot locking after the solve (RenavOptions::foot_lock_ramp): on a rig with
// thighs, shins and feet whose predictor reports contact everywhere, the feet
// travel less on the ground than without it, and the root path is untouched.
TEST(Renavigate, FeetInContactAreLocked) {
  Skeleton s;
  s.names = {"Hips", "Spine", "UpperLeg_L", "LowerLeg_L", "Foot_L", "UpperLeg_R", "LowerLeg_R", "Foot_R"};
  s.parents = {-1, 0, 0, 2, 3, 0, 5, 6};
  s.offsets = {{0, 0, 0},        {0, 0.2, 0},       {0.1, -0.05, 0},  {0, -0.42, 0.02},
               {0, -0.42, -0.02}, {-0.1, -0.05, 0}, {0, -0.42, 0.02}, {0, -0.42, -0.02}};
  const Motion ref = test::random_motion(s, 40, 30.0, 21);
  RigInfo rig = measure_rig(s, {&ref});
  rig.foot_thresholds = {10.0, 10.0};  // every height counts as low
  ASSERT_EQ(rig.num_feet(), 2);
  NemfModel model = test::tiny_prior(5, test::tiny_nemf_config(), rig);
  {
    at::NoGradGuard no_grad;
    for (auto& p : model.named_parameters())
      if (p.first == "gmp.output.bias") p.second.narrow(0, 4, 2).fill_(10.0f);  // contact everywhere
  }
  const auto path = line_path(40, 0.01);
  RenavOptions locked = quick(LatentOptimizer::Lbfgs, 10), free = locked;
  free.foot_lock_ramp = -1;
  const Motion a = renavigate(on_runtime(model), ref, path, 30.0, locked);
  const Motion b = renavigate(on_runtime(model), ref, path, 30.0, free);
  const auto travel = [](const Motion& m, int foot) {
    const GlobalPose pose = forward_kinematics(m);
    double sum = 0.0;
    for (int f = 1; f < m.num_frames(); ++f) {
      const Eigen::Vector3d d = pose.position(f, foot) - pose.position(f - 1, foot);
      sum += std::hypot(d.x(), d.z());
    }
    return sum;
  };
  for (int foot : {4, 7}) EXPECT_LT(travel(a, foot), 0.5 * travel(b, foot)) << "foot " << foot;
  for (int f = 0; f < a.num_frames(); ++f) EXPECT_EQ(a.root_positions[f], b.root_positions[f]) << f;
}

TEST(RunRenav, EntryPointAndErrors) {
  auto model = tiny_model();
  const Motion ref = test::random_motion(model->rig().skeleton, 32, 30.0, 16);
  TaskContext ctx;
  ctx.model = test::shared_runtime_of(*model);
  RenavReport report;
  const Motion out = run_renav(ref, line_path(20, 0.05), 0.0, "", ctx, &report);  // default method, reference fps
  EXPECT_EQ(out.num_frames(), 20);
  EXPECT_EQ(out.fps, 30.0);
  EXPECT_LT(report.windows[0].final_energy, report.windows[0].initial_energy);
  EXPECT_EQ(renav_methods().front(), "nemf");
  std::atomic<int> stop{1};
  TaskContext cancelled = ctx;
  cancelled.cancel = &stop;
  EXPECT_THROW(run_renav(ref, line_path(20, 0.05), 0.0, "nemf-adam", cancelled), CancelledError);

  const auto path = line_path(20, 0.05);
  EXPECT_NE(input_error([&] { run_renav(ref, path, 0, "magic", ctx); }).find("unknown re-navigation method 'magic'"),
            std::string::npos);
  EXPECT_NE(input_error([&] { run_renav(ref, path, 0, "nemf", TaskContext{}); }).find("needs a model"),
            std::string::npos);
  EXPECT_NE(input_error([&] { run_renav(ref, {{0, 0}}, 0, "", ctx); }).find("at least two points"), std::string::npos);
  EXPECT_NE(input_error([&] { run_renav(ref, {{0, 0}, {INFINITY, 1}}, 0, "", ctx); }).find("not finite"),
            std::string::npos);
  EXPECT_NE(input_error([&] { run_renav(ref, path, std::nan(""), "", ctx); }).find("frame rate"), std::string::npos);
  Skeleton other = test::small_skeleton();
  other.names[2] = "Neck";
  const Motion stranger = test::random_motion(other, 32, 30.0, 17);
  // Another rig is retargeted to the model's, which needs the model's rig anatomy.
  EXPECT_NE(input_error([&] { run_renav(stranger, path, 0, "", ctx); }).find("no rig anatomy"), std::string::npos);
  EXPECT_NE(input_error([&] { run_renav(ref.slice(0, 1), path, 0, "", ctx); }).find("at least two frames"),
            std::string::npos);
  RenavOptions bad;
  bad.inits = {"psychic"};
  EXPECT_NE(bad.validate().find("psychic"), std::string::npos);
  EXPECT_THROW(renavigate(on_runtime(*model), ref, path, 30.0, bad), InputError);
}

}  // namespace
}  // namespace mf
