// The trajectory as a task input: the CSV reader (tasks/constraints/trajectory_csv.h), the
// constraints file's "trajectory" member (tasks/constraints/constraint_spec.h), the rows
// the solvers follow (MotionConstraints::followed_trajectory), the window
// problem's rows and the trajectory energy terms (tasks/reference/energies.h), the
// report (tasks/constraints/constraint_report.h) and the refusal of methods that cannot
// follow a trajectory (tasks/methods/jobs.h run_constrained).
#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "prior/model/nemf.h"
#include "prior/model/representation.h"
#include "prior/motion/errors.h"
#include "tasks/constraints/constraint_report.h"
#include "tasks/constraints/constraint_spec.h"
#include "tasks/constraints/trajectory_csv.h"
#include "tasks/reference/energies.h"
#include "tasks/methods/jobs.h"
#include "tests/test_util.h"

namespace mf {
namespace {

// The message of the InputError `f` throws ("" and a failure if none).
template <typename F>
std::string error_of(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return "";
}

TEST(TrajectoryCsv, ParsesRowsCommentsAndHeader) {
  const std::string text =
      "\xEF\xBB\xBF# a comment\n Frame, X, Z, Forward_X, Forward_Z \r\n0,1.5,-2,0,1\n\n3, +4, 5e-1, 2, 0\n";
  const std::vector<TrajectoryPoint> rows = parse_trajectory_csv(text, "t.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].frame, 0);
  EXPECT_DOUBLE_EQ(rows[0].x, 1.5);
  EXPECT_DOUBLE_EQ(rows[0].z, -2.0);
  EXPECT_EQ(rows[1].frame, 3);
  EXPECT_DOUBLE_EQ(rows[1].z, 0.5);
  EXPECT_DOUBLE_EQ(rows[1].forward_x, 2.0);  // not normalised here
}

TEST(TrajectoryCsv, EachErrorNamesItsLine) {
  const std::string h = "frame,x,z,forward_x,forward_z\n";
  const std::pair<std::string, std::string> cases[] = {
      {"0,1,2,0,1\n", "t.csv:1: expected the header 'frame,x,z,forward_x,forward_z'"},
      {"frame,x,z\n0,1,2\n", "t.csv:1: expected the header"},
      {h + "0,1,2,0\n", "t.csv:2: expected 5 comma-separated fields"},
      {h + "0,1,2,0,1,7\n", "t.csv:2: expected 5 comma-separated fields"},
      {h + "0,1,2,0,1\n1,nan,2,0,1\n", "t.csv:3: non-finite value"},
      {h + "0,1,inf,0,1\n", "t.csv:2: non-finite value"},
      {h + "0,1,2,0,0\n", "t.csv:2: the facing direction (forward_x, forward_z) has zero length"},
      {h + "4,1,2,0,1\n4,1,2,0,1\n", "t.csv:3: frame 4 is given twice"},
      {h + "4,1,2,0,1\n# c\n2,1,2,0,1\n", "t.csv:4: frame 2 comes after frame 4"},
      {h + "-1,1,2,0,1\n", "t.csv:2: the frame must be a non-negative integer"},
      {h + "1.5,1,2,0,1\n", "t.csv:2: the frame must be a non-negative integer"},
      {h + "1,a,2,0,1\n", "t.csv:2: 'x' must be a number"},
      {h + "1,1,2,,1\n", "t.csv:2: 'forward_x' must be a number"},
      {h, "t.csv: the trajectory has no rows"},
      {"# only\n", "t.csv: empty"},
  };
  for (const auto& [text, message] : cases) {
    const std::string e = error_of([&] { parse_trajectory_csv(text, "t.csv"); });
    EXPECT_EQ(e.rfind(message, 0), 0u) << "'" << text << "' gave '" << e << "'";
  }
  EXPECT_NE(error_of([] { read_trajectory_csv("/nonexistent/t.csv"); }).find("/nonexistent/t.csv"), std::string::npos);
}

TEST(TrajectorySpec, JsonMemberRoundTripsAndResolvesInTheInputsUnit) {
  const std::string json = R"({"keys": [{"frame": 0}, {"frame": 20}], "trajectory": [
      {"frame": 12, "x": 150, "z": -20, "forward_x": 0, "forward_z": 2},
      {"frame": 5, "x": 100, "z": 10.5, "forward_x": 1, "forward_z": 0}]})";
  const ConstraintSpec spec = ConstraintSpec::parse_json(json, "c.json");
  ASSERT_EQ(spec.trajectory.size(), 2u);
  const std::string again = spec.to_json();
  EXPECT_EQ(ConstraintSpec::parse_json(again, "again").to_json(), again);
  EXPECT_NE(again.find("\"trajectory\""), std::string::npos);
  // No trajectory: no member (older documents keep their bytes).
  EXPECT_EQ(ConstraintSpec::parse_json(R"({"keys": [{"frame": 0}]})").to_json().find("trajectory"), std::string::npos);

  const MotionConstraints c = spec.resolve(test::small_skeleton(), 0.01);  // centimetres
  ASSERT_EQ(c.trajectory.size(), 2u);
  EXPECT_EQ(c.trajectory[0].frame, 5);  // sorted
  EXPECT_DOUBLE_EQ(c.trajectory[0].x, 1.0);
  EXPECT_DOUBLE_EQ(c.trajectory[0].z, 0.105);
  EXPECT_DOUBLE_EQ(c.trajectory[1].forward_z, 2.0);
  EXPECT_NO_THROW(c.validate(21, test::small_skeleton().num_joints()));

  for (const auto& [bad, message] : std::vector<std::pair<std::string, std::string>>{
           {R"({"trajectory": [{"frame": 1, "x": 0, "z": 0, "forward_x": 0}]})", "needs \"forward_z\""},
           {R"({"trajectory": [{"frame": 1, "x": 0, "z": 0, "forward_x": 0, "forward_z": 0}]})", "zero length"},
           {R"({"trajectory": [{"frame": 1, "x": "a", "z": 0, "forward_x": 0, "forward_z": 1}]})", "finite number"},
           {R"({"trajectory": [{"frame": 1, "x": 0, "z": 0, "forward_x": 0, "forward_z": 1, "y": 0}]})",
            "unknown field \"y\""},
           {R"({"trajectory": {"frame": 1}})", "\"trajectory\" must be an array"}}) {
    const std::string e = error_of([&] { ConstraintSpec::parse_json(bad, "c.json"); });
    EXPECT_EQ(e.rfind("c.json:", 0), 0u) << e;
    EXPECT_NE(e.find(message), std::string::npos) << e;
  }
  // Rows from two sources at one frame: validation says so.
  ConstraintSpec twice = spec;
  twice.append(spec);
  const std::string e = error_of([&] { twice.resolve(test::small_skeleton(), 0.01).validate(21, 7); });
  EXPECT_NE(e.find("strictly increasing (5 is followed by 5)"), std::string::npos) << e;
}

MotionConstraints keys_and_rows() {
  MotionConstraints c = MotionConstraints::full_pose({0, 10});
  PoseKey rotation_only;  // fixes no root position: its row is followed
  rotation_only.frame = 6;
  rotation_only.joints = {2};
  rotation_only.root_position = false;
  c.keys.insert(c.keys.begin() + 1, rotation_only);
  for (int f : {0, 3, 6, 10}) c.trajectory.push_back({f, 0.1 * f, -0.2 * f, 0.0, 1.0});
  return c;
}

TEST(TrajectoryRows, RowsAtKnownRootPositionsAreIgnored) {
  const MotionConstraints c = keys_and_rows();
  const std::vector<TrajectoryPoint> followed = c.followed_trajectory();
  ASSERT_EQ(followed.size(), 2u);
  EXPECT_EQ(followed[0].frame, 3);
  EXPECT_EQ(followed[1].frame, 6);
  EXPECT_TRUE(c.fixes_root_position(10));
  EXPECT_FALSE(c.fixes_root_position(6));
}

TEST(TrajectoryRows, WindowProblemHoldsThemInTheCanonicalFrame) {
  NemfModel model = test::tiny_prior(11);
  const RigInfo& rig = model.rig();
  Motion m = test::random_motion(rig.skeleton, 12, 30.0, 4);
  MotionConstraints c = keys_and_rows();
  // A row exactly where the anchor (frame 0) stands, facing where it faces:
  // canonical (0, 0) facing +Z.
  const Eigen::Vector3d fwd = m.rotation(0, 0).normalized() * rig.root_forward;
  c.trajectory[1] = {3, m.root_positions[0].x(), m.root_positions[0].z(), 3 * fwd.x(), 3 * fwd.z()};
  const WindowProblem p = make_window_problem(rig, m, 0, 12, c, 0);
  ASSERT_EQ(p.num_trajectory(), 2);
  EXPECT_EQ(p.trajectory_frames[0].item<int64_t>(), 3);
  EXPECT_NEAR(p.trajectory_ground[0][0].item<float>(), 0.0f, 1e-5);
  EXPECT_NEAR(p.trajectory_ground[0][1].item<float>(), 0.0f, 1e-5);
  EXPECT_NEAR(p.trajectory_forward[0][0].item<float>(), 0.0f, 1e-5);
  EXPECT_NEAR(p.trajectory_forward[0][1].item<float>(), 1.0f, 1e-5);
}

TEST(TrajectoryRows, EnergyIsZeroOnTheDecodedPathAndGrowsAwayFromIt) {
  at::set_num_threads(1);
  NemfModel model = test::tiny_prior(11);
  const RigInfo& rig = model.rig();
  at::manual_seed(5);
  const at::Tensor zl = at::randn({1, 8}), zg = at::randn({1, 4});
  WindowProblem p;
  p.length = 24;
  p.anchor = 0;
  const DecodedWindow d = decode_window(model, p, zl, zg);
  // Rows at every other frame: the decoded root's ground position and facing.
  p.trajectory_frames = at::arange(1, 24, 2, at::kLong);
  const at::Tensor f = trajectory_features(test::window_rotations(d).select(1, 0), test::window_root_positions(d),
                                           rig.root_forward)
                           .index_select(0, p.trajectory_frames);
  p.trajectory_ground = f.narrow(1, 0, 2).clone();
  p.trajectory_forward = f.narrow(1, 2, 2).clone();
  EnergyWeights w;
  w.rotation = w.position = w.root_orientation = w.root_translation = w.effector = w.contact = 0.0;
  w.trajectory = 1.0;
  w.trajectory_facing = 1.0;
  const EnergyTerms at_path = evaluate_energy(model, p, w, zl, zg);
  ASSERT_EQ(at_path.terms.size(), 2u);
  EXPECT_NEAR(at_path.total.item<double>(), 0.0, 1e-8);
  // 30 cm to the side on every row: the ground term is 0.09 m^2, facing untouched.
  WindowProblem moved = p;
  moved.trajectory_ground = p.trajectory_ground + at::tensor({0.3f, 0.0f});
  const EnergyTerms off = evaluate_energy(model, moved, w, zl, zg);
  EXPECT_NEAR(off.terms[0].second.item<double>(), 0.09, 1e-4);
  EXPECT_NEAR(off.terms[1].second.item<double>(), 0.0, 1e-8);
  // Turned 90 degrees: |a - b|^2 = 2 (1 - cos 90) = 2.
  WindowProblem turned = p;
  turned.trajectory_forward = at::stack({p.trajectory_forward.select(1, 1), -p.trajectory_forward.select(1, 0)}, 1);
  EXPECT_NEAR(evaluate_energy(model, turned, w, zl, zg).terms[1].second.item<double>(), 2.0, 1e-4);
  // Gradients reach the codes.
  const at::Tensor zl2 = zl.clone().requires_grad_(true);
  evaluate_energy(model, moved, w, zl2, zg).total.backward();
  EXPECT_GT(zl2.grad().abs().sum().item<double>(), 0.0);
}

TEST(TrajectoryRows, ReportMeasuresGroundDistanceAndFacing) {
  const Skeleton s = test::small_skeleton();
  Motion m = Motion::identity(s, 11, 30.0);
  for (int f = 0; f <= 10; ++f) m.root_positions[f] = Eigen::Vector3d(0.1 * f, 0.9, 0.0);
  m.rotation(3, 0) = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()));  // faces +X
  const MotionConstraints c = keys_and_rows();  // rows at 3 (0.3, -0.6) and 6 (0.6, -1.2), facing +Z
  const TrajectoryError e = trajectory_error(m, c);
  EXPECT_EQ(e.rows, 2);
  EXPECT_NEAR(e.max_cm, 120.0, 1e-6);
  EXPECT_NEAR(e.mean_cm, 90.0, 1e-6);
  EXPECT_NEAR(e.facing_max_deg, 90.0, 1e-6);
  EXPECT_NEAR(e.facing_mean_deg, 45.0, 1e-6);
  EXPECT_EQ(measure_constraints(m, c, m).trajectory.rows, 2);
}

TEST(TrajectoryRows, MethodsThatCannotFollowOneRefuseIt) {
  const Skeleton s = test::small_skeleton();
  const Motion m = test::random_motion(s, 11, 30.0, 2);
  MotionConstraints c = MotionConstraints::full_pose({0, 10});
  c.trajectory.push_back({5, 0.0, 0.0, 0.0, 1.0});
  const std::string e = error_of([&] { run_constrained(m, c, "interp", 0); });
  EXPECT_NE(e.find("method 'interp' cannot follow a trajectory; the methods that can: nemf, nemf-adam"),
            std::string::npos)
      << e;
  // Without a model the default method is interpolation: the same refusal.
  EXPECT_NE(error_of([&] { run_constrained(m, c, "", 0); }).find("cannot follow a trajectory"), std::string::npos);
}

}  // namespace
}  // namespace mf
