// The benchmark protocol (bench/protocol.h) on tiny synthetic data sets.
#include "bench/protocol.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <sstream>
#include <string>

#include "prior/model/nemf.h"
#include "prior/model/representation.h"
#include "bench/options.h"
#include "prior/motion/errors.h"
#include "prior/motion/motion_bvh.h"
#include "prior/rig/mirror.h"
#include "tests/runtime_test_util.h"
#include "tests/test_util.h"

namespace mf::bench {
namespace {

Clip make_clip(const std::string& name, Motion motion) {
  Clip c;
  c.name = name;
  c.motion = std::move(motion);
  return c;
}

// A fixed random pose (frame 0 of a random motion) held still while the root
// moves along a straight line at constant speed: interpolation is exact on it.
Motion linear_root_motion(int frames, uint32_t seed) {
  const Motion r = test::random_motion(test::small_skeleton(), frames, 30.0, seed);
  Motion m = r;
  for (int f = 0; f < frames; ++f) {
    for (int j = 0; j < m.num_joints(); ++j) m.rotation(f, j) = r.rotation(0, j);
    m.root_positions[f] = Eigen::Vector3d(0.3 + 0.02 * f, 0.9, -1.0 + 0.035 * f);
  }
  return m;
}

EvalStats small_stats() {
  std::vector<Clip> train;
  train.push_back(make_clip("t1.bvh", test::random_motion(test::small_skeleton(), 120, 30.0, 11)));
  train.push_back(make_clip("t2.bvh", test::random_motion(test::small_skeleton(), 90, 30.0, 12)));
  return compute_eval_stats(train);
}

TEST(ProtocolTest, WindowsStartEveryStrideAndFit) {
  const Skeleton s = test::small_skeleton();
  std::vector<Clip> clips = {make_clip("a", Motion::identity(s, 100, 30)), make_clip("b", Motion::identity(s, 16, 30)),
                             make_clip("c", Motion::identity(s, 15, 30))};
  const std::vector<Window> w = protocol_windows(clips, 16, 40);
  ASSERT_EQ(w.size(), 4u);  // a: 0, 40, 80 (80 + 16 <= 100); b: 0; c: none
  EXPECT_EQ(w[2].clip, 0);
  EXPECT_EQ(w[2].start, 80);
  EXPECT_EQ(w[3].clip, 1);
  EXPECT_EQ(w[3].start, 0);
  EXPECT_EQ(w[3].length, 16);
  EXPECT_TRUE(protocol_windows(clips, 101, 40).empty());
  EXPECT_THROW(protocol_windows(clips, 10, 0), InputError);

  std::vector<Window> ten;
  for (int i = 0; i < 10; ++i) ten.push_back({i, 0, 5});
  const std::vector<Window> capped = cap_windows(ten, 3);
  ASSERT_EQ(capped.size(), 3u);
  EXPECT_EQ(capped[0].clip, 0);
  EXPECT_EQ(capped[1].clip, 3);
  EXPECT_EQ(capped[2].clip, 6);
  EXPECT_EQ(cap_windows(ten, 0).size(), 10u);
  EXPECT_EQ(cap_windows(ten, 20).size(), 10u);
}

TEST(ProtocolTest, SparseKeyframesIncludeTheLastFrame) {
  EXPECT_EQ(sparse_keyframes(128, 30), (std::vector<int>{0, 30, 60, 90, 120, 127}));
  EXPECT_EQ(sparse_keyframes(11, 5), (std::vector<int>{0, 5, 10}));
  EXPECT_EQ(sparse_keyframes(2, 5), (std::vector<int>{0, 1}));
  EXPECT_THROW(sparse_keyframes(1, 5), InputError);
  EXPECT_THROW(sparse_keyframes(10, 0), InputError);
}

TEST(ProtocolTest, HiddenFramesCarryNoTruth) {
  const Motion m = test::random_motion(test::small_skeleton(), 6, 30.0, 5);
  const Motion h = hide_unknown_frames(m, {1, 4});
  EXPECT_TRUE(h.root_positions[0].isApprox(m.root_positions[1]));
  EXPECT_TRUE(h.root_positions[2].isApprox(m.root_positions[1]));
  EXPECT_TRUE(h.root_positions[5].isApprox(m.root_positions[4]));
  EXPECT_TRUE(h.rotation(3, 2).isApprox(Eigen::Quaterniond::Identity()));
  EXPECT_TRUE(h.rotation(4, 2).isApprox(m.rotation(4, 2)));
  EXPECT_TRUE(h.rotation(1, 0).isApprox(m.rotation(1, 0)));
}

TEST(ProtocolTest, GapFillingCountsWindowsAndInterpIsExactOnLinearRoot) {
  const EvalStats stats = small_stats();
  std::vector<Clip> val = {make_clip("v1", linear_root_motion(100, 21)), make_clip("v2", linear_root_motion(60, 22))};
  ProtocolOptions options;
  options.gap_lengths = {5, 30, 90};
  const TaskResult r = run_gap_filling(val, stats, "interp", options);
  EXPECT_EQ(r.method, "interp");
  EXPECT_GE(r.threads, 1);
  ASSERT_EQ(r.rows.size(), 3u);
  // T = 5: 16 frames: v1 at 0, 40, 80; v2 at 0, 40. T = 30: 41 frames: v1 at 0,
  // 40 (40 + 41 <= 100); v2 at 0. T = 90: 101 frames: none.
  EXPECT_EQ(r.rows[0].parameter, 5);
  EXPECT_EQ(r.rows[0].metrics.windows, 5);
  EXPECT_EQ(r.rows[1].metrics.windows, 3);
  EXPECT_EQ(r.rows[2].metrics.windows, 0);
  for (int i = 0; i < 2; ++i) {
    const MetricSummary& m = r.rows[i].metrics;
    EXPECT_NEAR(m.mpjpe_cm, 0.0, 1e-6) << i;
    EXPECT_NEAR(m.l2p, 0.0, 1e-6) << i;
    EXPECT_NEAR(m.l2q, 0.0, 1e-6) << i;
    EXPECT_NEAR(m.npss, 0.0, 1e-6) << i;
    EXPECT_NEAR(m.known.position_max_cm, 0.0, 1e-6) << i;
    EXPECT_NEAR(m.skating_cm, m.truth_skating_cm, 1e-6) << i;
  }

  options.max_windows = 2;
  const TaskResult capped = run_gap_filling(val, stats, "interp", options);
  EXPECT_EQ(capped.rows[0].metrics.windows, 2);
  EXPECT_EQ(capped.rows[1].metrics.windows, 2);
}

TEST(ProtocolTest, BaselinesKeepKnownFramesAndInterpBeatsZeroVelocity) {
  const EvalStats stats = small_stats();
  std::vector<Clip> val;
  for (uint32_t seed = 30; seed < 33; ++seed) {
    val.push_back(make_clip("v" + std::to_string(seed), test::random_motion(test::small_skeleton(), 140, 30.0, seed)));
  }
  ProtocolOptions options;
  options.gap_lengths = {5, 15, 30};
  options.keyframe_spacings = {5, 20};
  for (Task task : all_tasks()) {
    const TaskResult interp = run_task(task, val, stats, "interp", options);
    const TaskResult zerovel = run_task(task, val, stats, "zerovel", options);
    ASSERT_EQ(interp.rows.size(), zerovel.rows.size());
    for (size_t i = 0; i < interp.rows.size(); ++i) {
      const MetricSummary& a = interp.rows[i].metrics;
      const MetricSummary& b = zerovel.rows[i].metrics;
      ASSERT_GT(a.windows, 0) << task_name(task) << " row " << i;
      EXPECT_EQ(a.windows, b.windows);
      EXPECT_LT(a.known.position_max_cm, 1e-4) << task_name(task);
      EXPECT_LT(a.known.rotation_max_deg, 1e-3) << task_name(task);
      EXPECT_LT(b.known.position_max_cm, 1e-4) << task_name(task);
      EXPECT_LT(b.known.rotation_max_deg, 1e-3) << task_name(task);
      EXPECT_GT(a.l2p, 0.0);
      EXPECT_LT(a.l2p, b.l2p) << task_name(task) << " row " << i;
      EXPECT_LT(a.mpjpe_cm, b.mpjpe_cm) << task_name(task) << " row " << i;
      EXPECT_NEAR(a.truth_skating_cm, b.truth_skating_cm, 1e-12);
    }
  }
  // Window counts: sparse 128-frame windows at 0 only (40 + 128 > 140), resample
  // 65-frame windows at 0 and 40 (80 + 65 > 140).
  EXPECT_EQ(run_sparse_keyframes(val, stats, "interp", options).rows[0].metrics.windows, 3);
  const TaskResult res = run_resampling(val, stats, "interp", options);
  ASSERT_EQ(res.rows.size(), 1u);
  EXPECT_EQ(res.rows[0].parameter, 2);  // every other frame kept
  EXPECT_EQ(res.rows[0].metrics.windows, 6);
}

TEST(ProtocolTest, ResamplingOfLinearRootIsExact) {
  const EvalStats stats = small_stats();
  std::vector<Clip> val = {make_clip("v", linear_root_motion(70, 40))};
  const TaskResult r = run_resampling(val, stats, "interp");
  ASSERT_EQ(r.rows.size(), 1u);
  EXPECT_EQ(r.rows[0].metrics.windows, 1);
  EXPECT_NEAR(r.rows[0].metrics.mpjpe_cm, 0.0, 1e-6);
  EXPECT_NEAR(r.rows[0].metrics.known.position_max_cm, 0.0, 1e-6);
}

TEST(ProtocolTest, TableNamesMethodThreadsAndRows) {
  TaskResult r;
  r.task = Task::Sparse;
  r.method = "zerovel";
  r.threads = 2;
  RowResult row;
  row.parameter = 15;
  row.metrics.windows = 7;
  row.metrics.l2p = 1.23456;
  row.metrics.npss = 0.01234;
  row.ms_per_window = 0.5;
  r.rows.push_back(row);
  const std::string t = format_table(r);
  EXPECT_NE(t.find("`zerovel`"), std::string::npos);
  EXPECT_NE(t.find("torch threads: 2"), std::string::npos);
  EXPECT_NE(t.find("| 15 | 7 | 1.235 |"), std::string::npos) << t;
  EXPECT_NE(t.find("0.0123"), std::string::npos);
  EXPECT_EQ(t.find("L2P xz"), std::string::npos);
  r.rows[0].metrics.l2p_horizontal = 0.5;
  r.rows[0].metrics.l2p_vertical = 1.125;
  const std::string wide = format_table(r, true);
  EXPECT_NE(wide.find("| L2P | L2P xz | L2P y | L2Q |"), std::string::npos) << wide;
  EXPECT_NE(wide.find("| 15 | 7 | 1.235 | 0.500 | 1.125 |"), std::string::npos) << wide;
  EXPECT_EQ(task_from_name("resample"), Task::Resample);
  EXPECT_THROW(task_from_name("nope"), InputError);
}

TEST(ProtocolTest, StatsTableListsJointsAndFeet) {
  EvalStats stats;
  stats.joint_names = {"Hips", "Foot_L"};
  stats.position_mean = {0, 0.9, 0, 0.1, 0.12, 0};
  stats.position_std = {0.5, 0.025, 0.1, 0.5, 0.05, 0.1};
  stats.feet = {{1, 8.0}};
  stats.standing_height = {0.1174};
  const std::string t = format_eval_stats(stats);
  EXPECT_NE(t.find("| Hips | 0.0 | 90.0 | 0.0 | 50.0 | 2.5 | 10.0 | | |"), std::string::npos) << t;
  EXPECT_NE(t.find("| Foot_L | 10.0 | 12.0 | 0.0 | 50.0 | 5.0 | 10.0 | 11.74 | 8 |"), std::string::npos) << t;
}

TEST(ProtocolTest, TheContextReachesMethodsThatNeedTheModel) {
  const EvalStats stats = small_stats();
  std::vector<Clip> val = {make_clip("v", test::random_motion(test::small_skeleton(), 110, 30.0, 50))};
  EXPECT_TRUE(method_supports("prior", Task::Resample));
  EXPECT_FALSE(method_supports("prior", Task::Gap));
  EXPECT_TRUE(method_supports("interp", Task::Sparse));
  EXPECT_FALSE(method_supports("no-such-method", Task::Resample));
  // Without a model in the context the prior's method refuses to run.
  EXPECT_THROW(run_resampling(val, stats, "prior"), InputError);
  TaskContext ctx;
  ctx.model = test::shared_runtime_of(test::tiny_prior());
  const TaskResult r = run_task(Task::Resample, val, stats, "prior", ProtocolOptions{}, ctx);
  ASSERT_EQ(r.rows.size(), 1u);
  EXPECT_EQ(r.rows[0].metrics.windows, 2);  // 65-frame windows at 0 and 40
  // The prior's resampling keeps the input frames exactly.
  EXPECT_LT(r.rows[0].metrics.known.position_max_cm, 1e-6);
  EXPECT_LT(r.rows[0].metrics.known.rotation_max_deg, 1e-6);
  EXPECT_GT(r.rows[0].metrics.mpjpe_cm, 0.0);
}

// Splits CSV text into rows of cells (no quoting in the window log).
std::vector<std::vector<std::string>> csv_rows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::vector<std::string> cells;
    std::string cell;
    std::istringstream in(line);
    while (std::getline(in, cell, ',')) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.push_back("");
    rows.push_back(cells);
  }
  return rows;
}

TEST(ProtocolTest, WindowLogHasOneRowPerWindowAndMethod) {
  const EvalStats stats = small_stats();
  std::vector<Clip> val = {make_clip("v1", linear_root_motion(100, 21)), make_clip("v2", linear_root_motion(60, 22))};
  WindowLog log("bandai", {"native", ""});
  ProtocolOptions options;
  options.gap_lengths = {5, 30};
  options.window_log = &log;
  run_gap_filling(val, stats, "interp", options);
  run_gap_filling(val, stats, "zerovel", options);
  const auto rows = csv_rows(log.csv());
  const std::vector<std::string> header = {"dataset", "rig", "content", "clip", "task", "row",
                                           "method", "start", "l2p", "l2q", "l2p_to_interp", "key_motion_cm",
                                           "seam_cm"};
  ASSERT_EQ(rows.size(), 1u + 2 * (5 + 3));  // windows of T = 5 and 30 (GapFillingCounts...), two methods
  EXPECT_EQ(rows[0], header);
  for (size_t i = 1; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), header.size()) << i;
    EXPECT_EQ(rows[i][0], "bandai");
    EXPECT_EQ(rows[i][4], "gap");
  }
  EXPECT_EQ(rows[1][3], "v1");
  EXPECT_EQ(rows[1][5], "5");
  EXPECT_EQ(rows[1][6], "interp");
  EXPECT_EQ(rows[1][10], "");  // interpolation is the reference itself
  // Interpolation is exact on these clips: zero velocity's distance to it is its error.
  for (const WindowRecord& r : log.records()) {
    EXPECT_GT(r.key_motion_cm, 0.0);
    if (r.method == "interp") {
      EXPECT_NEAR(r.l2p, 0.0, 1e-6);
      EXPECT_NEAR(r.seam_cm, 0.0, 1e-6);  // it moves at the keys' own pace
    } else {
      EXPECT_GT(r.l2p, 0.0);
      EXPECT_NEAR(r.l2p_to_interp, r.l2p, 1e-6);
      EXPECT_GT(r.seam_cm, 0.5 * r.key_motion_cm);  // holds, then makes the whole move in one frame
    }
  }
}

TEST(ProtocolTest, WindowLogKeepsTheSolversEnergyTerms) {
  const EvalStats stats = small_stats();
  std::vector<Clip> val = {make_clip("v", test::random_motion(test::small_skeleton(), 40, 30.0, 50))};
  TaskContext ctx;
  ctx.model = test::shared_runtime_of(test::tiny_prior());
  ctx.max_iterations = 2;
  WindowLog log("bandai");
  ProtocolOptions options;
  options.gap_lengths = {5};
  options.window_log = &log;
  run_gap_filling(val, stats, "nemf", options, ctx);
  ASSERT_EQ(log.records().size(), 1u);  // 16 frames at 0 (40 would need 56)
  const auto rows = csv_rows(log.csv());
  ASSERT_EQ(rows.size(), 2u);
  const auto column = std::find(rows[0].begin(), rows[0].end(), "final.rotation");
  ASSERT_NE(column, rows[0].end());
  EXPECT_GE(std::stod(rows[1][column - rows[0].begin()]), 0.0);
  EXPECT_NE(std::find(rows[0].begin(), rows[0].end(), "initial.rotation"), rows[0].end());
}

TEST(ProtocolTest, ResamplingRowsPerFactorKeepEveryKthFrame) {
  const EvalStats stats = small_stats();
  std::vector<Clip> val = {make_clip("v", test::random_motion(test::small_skeleton(), 110, 30.0, 51))};
  ProtocolOptions o;
  o.resample_ratios = {{2, 1}, {4, 1}};
  const TaskResult interp = run_resampling(val, stats, "interp", o), cubic = run_resampling(val, stats, "cubic", o);
  ASSERT_EQ(interp.rows.size(), 2u);
  ASSERT_EQ(cubic.rows.size(), 2u);
  for (size_t r = 0; r < 2; ++r) {
    EXPECT_EQ(interp.rows[r].parameter, o.resample_ratios[r].in_step);
    EXPECT_EQ(interp.rows[r].metrics.windows, 2);
    EXPECT_LT(cubic.rows[r].metrics.known.position_max_cm, 1e-6);
    // The smooth sinusoids of the test motion: the spline beats the chords.
    EXPECT_LT(cubic.rows[r].metrics.l2p, interp.rows[r].metrics.l2p);
  }
  // Fewer input frames, larger errors.
  EXPECT_GT(interp.rows[1].metrics.l2p, interp.rows[0].metrics.l2p);
  EXPECT_NE(format_table(cubic, false).find("every k-th frame"), std::string::npos);
  o.resample_ratios = {{2, 2}};
  EXPECT_THROW(run_resampling(val, stats, "interp", o), InputError);
}

TEST(ProtocolTest, ResamplingByRatiosThatAreNotWhole) {
  const EvalStats stats = small_stats();
  std::vector<Clip> val = {make_clip("v", test::random_motion(test::small_skeleton(), 110, 30.0, 51))};
  ProtocolOptions o;
  // 3:2 upsamples 10 -> 15 fps in 67-frame windows (1 + a multiple of 6); 4:5
  // downsamples 7.5 -> 6 fps in 81-frame windows; 3 alone needs 67 frames too.
  o.resample_ratios = {{3, 2}, {4, 5}, {3, 1}};
  const TaskResult interp = run_resampling(val, stats, "interp", o), cubic = run_resampling(val, stats, "cubic", o);
  ASSERT_EQ(cubic.rows.size(), 3u);
  EXPECT_EQ(cubic.rows[0].label, "3:2");
  EXPECT_EQ(cubic.rows[1].label, "4:5");
  EXPECT_EQ(cubic.rows[2].label, "3");
  EXPECT_EQ(cubic.rows[0].metrics.windows, 2);  // 67-frame windows at 0 and 40
  EXPECT_EQ(cubic.rows[1].metrics.windows, 1);  // 81 frames fit once
  for (size_t r = 0; r < 3; ++r) {
    // Output frames on an input frame (every 6th ground-truth frame for 3:2) come out exactly.
    EXPECT_LT(cubic.rows[r].metrics.known.position_max_cm, 1e-6) << r;
    EXPECT_LT(cubic.rows[r].metrics.l2p, interp.rows[r].metrics.l2p) << r;
    EXPECT_GT(interp.rows[r].metrics.l2p, 0.0) << r;
  }
  const std::string table = format_table(cubic, false);
  EXPECT_NE(table.find("| 3:2 | 2 |"), std::string::npos) << table;
  EXPECT_NE(table.find("| 4:5 | 1 |"), std::string::npos) << table;
}

TEST(ProtocolTest, ParsesResampleRatios) {
  EXPECT_EQ(parse_resample_ratio("5:4").in_step, 5);
  EXPECT_EQ(parse_resample_ratio("5:4").out_step, 4);
  EXPECT_EQ(parse_resample_ratio("2").out_step, 1);
  EXPECT_EQ(parse_resample_ratio("4:5").label(), "4:5");
  for (const char* bad : {"", ":", "5:", ":4", "0:1", "3:3", "1", "2.5", "a:b", "5:4:3", "-2", "2000"})
    EXPECT_THROW(parse_resample_ratio(bad), InputError) << bad;
}

// --split validation-mirror measures on the validation clips' mirrors (the
// twists chosen from the training split): same clips and lengths, every joint
// where its counterpart's reflection was; the other splits are the data's own.
TEST(ProtocolTest, MirroredValidationSplitReflectsTheValidationClips) {
  const Motion walk = read_motion(std::string(MF_SOURCE_DIR) + "/samples/walk_keyframes.bvh");
  Dataset data;
  data.skeleton = walk.skeleton;
  data.train.push_back(make_clip("train.bvh", walk));
  data.validation.push_back(make_clip("a.bvh", walk.slice(0, 40)));
  data.validation.push_back(make_clip("b.bvh", walk.slice(20, 61)));
  SplitChoice choice;
  EXPECT_EQ(&choice.clips(data), &data.validation);
  choice.split = "train";
  EXPECT_EQ(&choice.clips(data), &data.train);
  choice.split = "validation-mirror";
  const std::vector<Clip>& mirrored = choice.clips(data);
  ASSERT_EQ(mirrored.size(), 2u);
  EXPECT_EQ(mirrored[1].name, "b.bvh#mirror");
  const MirrorMap map = mirror_map(walk.skeleton, mean_local_rotations({&walk}));
  const Eigen::Matrix3d M = Eigen::Vector3d(-1, 1, 1).asDiagonal();
  for (size_t c = 0; c < 2; ++c) {
    const Motion& original = data.validation[c].motion;
    ASSERT_EQ(mirrored[c].motion.num_frames(), original.num_frames());
    const GlobalPose a = forward_kinematics(original), b = forward_kinematics(mirrored[c].motion);
    double worst = 0.0, moved = 0.0;
    for (int f = 0; f < original.num_frames(); ++f)
      for (int j = 0; j < original.num_joints(); ++j) {
        worst = std::max(worst, (b.position(f, j) - M * a.position(f, map.counterpart[j])).norm());
        moved = std::max(moved, (b.position(f, j) - a.position(f, j)).norm());
      }
    EXPECT_LT(worst, 1e-9);
    EXPECT_GT(moved, 0.05);  // not the clip itself
  }
  EXPECT_EQ(&choice.clips(data), &mirrored);  // built once
}

}  // namespace
}  // namespace mf::bench
