// Transitions between two clips (tasks/transition/transition.h): two clips cut
// from one real clip at different places.
#include "tasks/transition/transition.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "bench/foreign_data.h"
#include "prior/data/dataset.h"
#include "prior/motion/errors.h"
#include "prior/motion/interpolation.h"
#include "prior/motion/motion_bvh.h"
#include "tests/runtime_test_util.h"
#include "tests/test_util.h"

namespace mf {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A real capture clip of at least 180 frames at 30 fps (the foreign capture's
// first validation clip that long), else the sample walk.
const Motion& source_clip() {
  static const Motion clip = [] {
    const std::string archive = default_foreign_archive();
    if (std::filesystem::exists(archive)) {
      const bench::ForeignData data = bench::load_foreign_data(archive, default_cache_dir(), 30.0, false);
      for (const bench::ForeignClip& c : data.validation)
        if (c.clip.motion.num_frames() >= 180) return c.clip.motion.slice(0, 180);
    }
    return read_motion(std::string(MF_SOURCE_DIR) + "/samples/walk_keyframes.bvh");
  }();
  return clip;
}

// The sample walk (hand-made, 61 frames): for the checks that need no real capture.
const Motion& sample_clip() {
  static const Motion clip = read_motion(std::string(MF_SOURCE_DIR) + "/samples/walk_keyframes.bvh");
  return clip;
}

// Clip A: the first 55% of a clip; clip B: from 40% to its end.
Motion clip_a(const Motion& from = sample_clip()) { return from.slice(0, from.num_frames() * 55 / 100); }
Motion clip_b(const Motion& from = sample_clip()) {
  return from.slice(from.num_frames() * 40 / 100, from.num_frames());
}

bool same_frames(const Motion& out, int out_begin, const Motion& in, int in_begin, int count) {
  const int J = in.num_joints();
  for (int f = 0; f < count; ++f) {
    if (out.root_positions[out_begin + f] != in.root_positions[in_begin + f]) return false;
    for (int j = 0; j < J; ++j)
      if (!out.rotation(out_begin + f, j).coeffs().isApprox(in.rotation(in_begin + f, j).coeffs(), 0.0)) return false;
  }
  return true;
}

double facing(const Motion& m, int f) {
  const Eigen::Vector3d v = m.rotation(f, 0).normalized() * Eigen::Vector3d::UnitZ();
  return std::atan2(v.x(), v.z());
}
double angle_between(double a, double b) { return std::abs(std::remainder(a - b, 2.0 * kPi)); }
double ground_step(const Motion& m, int f) {
  const Eigen::Vector3d d = m.root_positions[f + 1] - m.root_positions[f];
  return std::hypot(d.x(), d.z());
}

TransitionRequest request(int frames, TransitionRequest::Placement place = TransitionRequest::Placement::kAuto) {
  TransitionRequest r;
  r.frames = frames;
  r.place = place;
  return r;
}

TEST(Transition, KeepReturnsBothPartsBitForBit) {
  const Motion a = clip_a(source_clip()), b = clip_b(source_clip());
  TransitionRequest r = request(20, TransitionRequest::Placement::kKeep);
  r.from_frame = -3;
  r.to_frame = 4;
  const TransitionResult t = run_transition(a, b, r, "interp", 0);
  ASSERT_EQ(t.motions.size(), 1u);
  const Motion& out = t.motions[0];
  const int I = a.num_frames() - 3;
  EXPECT_EQ(t.from_frame, I);
  EXPECT_EQ(t.to_frame, 4);
  EXPECT_EQ(t.frames, 20);
  EXPECT_EQ(t.first_frame, I + 1);
  EXPECT_EQ(t.method, "interp");
  ASSERT_EQ(out.num_frames(), I + 1 + 20 + b.num_frames() - 4);
  EXPECT_EQ(out.fps, a.fps);
  EXPECT_TRUE(out.skeleton.same_as(a.skeleton));
  EXPECT_TRUE(test::all_finite(out));
  EXPECT_TRUE(same_frames(out, 0, a, 0, I + 1));
  EXPECT_TRUE(same_frames(out, I + 21, b, 4, b.num_frames() - 4));
  EXPECT_TRUE(t.warnings.empty()) << t.warnings.front();
}

// Cut where the clip moves at about the same speed and way at both seams (a
// placement carries the root on at the mean of the two velocities; it cannot
// reconcile a run with a stop); B then moved and turned away, which the
// placement undoes.
TEST(Transition, AutoPlacementContinuesAsEnd) {
  const Motion& src = source_clip();
  const Motion a = src.slice(0, src.num_frames() * 92 / 100);
  const Motion b = src.slice(src.num_frames() * 80 / 100, src.num_frames());
  Motion moved = b;
  const Eigen::Quaterniond away(Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitY()));
  for (int f = 0; f < moved.num_frames(); ++f) {
    moved.rotation(f, 0) = away * b.rotation(f, 0);
    moved.root_positions[f] = away * b.root_positions[f] + Eigen::Vector3d(3.0, 0.0, -2.0);
  }
  const Motion placed_moved = place_transition_clip(a, moved, a.num_frames() - 1, 0, 20);
  const int N = 20, I = a.num_frames() - 1;
  const TransitionResult t = run_transition(a, b, request(N), "interp", 0);
  const Motion& out = t.motions[0];
  ASSERT_TRUE(test::all_finite(out));
  EXPECT_TRUE(same_frames(out, 0, a, 0, I + 1));
  // B's part is B as placed, exactly.
  const Motion placed = place_transition_clip(a, b, I, 0, N);
  EXPECT_TRUE(same_frames(out, I + 1 + N, placed, 0, b.num_frames()));
  // Its heights are B's own; where B was and which way it faced do not matter.
  for (int f = 0; f < b.num_frames(); ++f) {
    EXPECT_EQ(placed.root_positions[f].y(), b.root_positions[f].y());
    EXPECT_LT((placed_moved.root_positions[f] - placed.root_positions[f]).norm(), 1e-9);
    EXPECT_LT(placed_moved.rotation(f, 0).angularDistance(placed.rotation(f, 0)), 1e-9);
  }
  // The clips' own largest frame-to-frame changes of facing and ground speed.
  double turn = 0, speed_change = 0;
  for (int f = 0; f + 1 < src.num_frames(); ++f) turn = std::max(turn, angle_between(facing(src, f + 1), facing(src, f)));
  for (int f = 0; f + 2 < src.num_frames(); ++f)
    speed_change = std::max(speed_change, std::abs(ground_step(src, f + 1) - ground_step(src, f)));
  const int J = I + 1 + N;  // B's first frame in the output
  EXPECT_LE(angle_between(facing(out, J), facing(out, I)), turn + 1e-3);
  // The root carries on at the seams' speeds: the transition's mean ground
  // speed against each clip's over the steps at its seam.
  const Eigen::Vector3d across = out.root_positions[J] - out.root_positions[I];
  const double transition_speed = std::hypot(across.x(), across.z()) / (N + 1);
  double speed_a = 0, speed_b = 0;
  for (int k = 0; k < kTransitionVelocityFrames; ++k) {
    speed_a += ground_step(out, I - 1 - k) / kTransitionVelocityFrames;
    speed_b += ground_step(out, J + k) / kTransitionVelocityFrames;
  }
  EXPECT_LE(std::abs(transition_speed - speed_a), speed_change) << transition_speed << " " << speed_a;
  EXPECT_LE(std::abs(transition_speed - speed_b), speed_change) << transition_speed << " " << speed_b;
}

TEST(Transition, ClipBAtAnotherFrameRateIsResampled) {
  const Motion a = clip_a(source_clip()), b = clip_b(source_clip());
  const Motion b60 = resample_cubic(b, 2 * b.fps, (b.num_frames() - 1) * 2 + 1);
  const TransitionResult t = run_transition(a, b60, request(15, TransitionRequest::Placement::kKeep), "interp", 0);
  const Motion& out = t.motions[0];
  EXPECT_EQ(out.fps, a.fps);
  ASSERT_EQ(out.num_frames(), a.num_frames() + 15 + b.num_frames());
  // Every second frame of the 60 fps copy is one of B's: resampled back, B exactly.
  EXPECT_TRUE(same_frames(out, a.num_frames() + 15, b, 0, b.num_frames()));
  ASSERT_FALSE(t.warnings.empty());
  EXPECT_NE(t.warnings[0].find("resampled"), std::string::npos) << t.warnings[0];
}

TEST(Transition, ClipBOnAnotherJointOrderOrOtherNames) {
  const Motion a = clip_a(), b = clip_b();
  const TransitionRequest r = request(12);
  const Motion plain = run_transition(a, b, r, "interp", 0).motions[0];
  // The same hierarchy under other names: mapped in order, with a warning.
  Motion renamed = b;
  for (std::string& n : renamed.skeleton.names) n = "x_" + n;
  const TransitionResult by_index = run_transition(a, renamed, r, "interp", 0);
  EXPECT_TRUE(same_frames(by_index.motions[0], 0, plain, 0, plain.num_frames()));
  ASSERT_FALSE(by_index.warnings.empty());
  EXPECT_NE(by_index.warnings[0].find("other names"), std::string::npos);
  // The joints in another order (children listed before a sibling's): matched by name.
  Motion reordered = b;
  const int J = b.num_joints();
  std::vector<int> order(J);  // new index -> old: the root, then the others reversed where parents allow
  std::vector<int> new_of(J, -1);
  int next = 0;
  std::function<void(int)> visit = [&](int j) {
    order[next] = j;
    new_of[j] = next++;
    std::vector<int> kids = b.skeleton.children()[j];
    std::reverse(kids.begin(), kids.end());
    for (int k : kids) visit(k);
  };
  visit(0);
  for (int n = 0; n < J; ++n) {
    reordered.skeleton.names[n] = b.skeleton.names[order[n]];
    reordered.skeleton.offsets[n] = b.skeleton.offsets[order[n]];
    reordered.skeleton.parents[n] = n == 0 ? -1 : new_of[b.skeleton.parents[order[n]]];
    for (int f = 0; f < b.num_frames(); ++f) reordered.rotation(f, n) = b.rotation(f, order[n]);
  }
  ASSERT_NO_THROW(reordered.skeleton.validate());
  const TransitionResult by_name = run_transition(a, reordered, r, "interp", 0);
  EXPECT_TRUE(same_frames(by_name.motions[0], 0, plain, 0, plain.num_frames()));
  EXPECT_TRUE(by_name.warnings.empty());
}

TEST(Transition, ClipBOnAnotherRigIsAClearError) {
  const Motion a = clip_a();
  const Motion other = test::random_motion(test::small_skeleton(), 40, 30.0, 3);
  try {
    run_transition(a, other, request(10), "interp", 0);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("clip B's rig differs from A's"), std::string::npos) << e.what();
  }
  // Same joint count and names, one joint under another parent.
  Motion moved = clip_b();
  const int last = moved.num_joints() - 1;
  ASSERT_GT(moved.skeleton.parents[last], 0);
  moved.skeleton.parents[last] = 0;
  try {
    run_transition(a, moved, request(10), "interp", 0);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'" + moved.skeleton.names[last] + "' has the parent"), std::string::npos)
        << e.what();
  }
}

TEST(Transition, OnlyTransitionGivesTheGeneratedFrames) {
  const Motion a = clip_a(), b = clip_b();
  TransitionRequest r = request(17);
  const Motion whole = run_transition(a, b, r, "interp", 0).motions[0];
  r.only_transition = true;
  const TransitionResult t = run_transition(a, b, r, "interp", 0);
  ASSERT_EQ(t.motions[0].num_frames(), 17);
  EXPECT_TRUE(same_frames(t.motions[0], 0, whole, a.num_frames(), 17));
  EXPECT_EQ(t.first_frame, a.num_frames());
}

TEST(Transition, AutomaticLengthIsInRangeAndReported) {
  const Motion a = clip_a(), b = clip_b();
  for (auto place : {TransitionRequest::Placement::kAuto, TransitionRequest::Placement::kKeep}) {
    const TransitionResult t = run_transition(a, b, request(0, place), "interp", 0);
    EXPECT_GE(t.frames, 10);
    EXPECT_LE(t.frames, 60);
    EXPECT_EQ(t.motions[0].num_frames(), a.num_frames() + t.frames + b.num_frames());
    ASSERT_FALSE(t.warnings.empty());
    EXPECT_NE(t.warnings.back().find("the transition has " + std::to_string(t.frames) + " frames"), std::string::npos)
        << t.warnings.back();
  }
  // The same pose at both seams: the shortest; at 60 fps the range doubles.
  EXPECT_EQ(automatic_transition_frames(a, a, a.num_frames() - 1, a.num_frames() - 1, false), 10);
  Motion a60 = a;
  a60.fps = 60.0;
  EXPECT_EQ(automatic_transition_frames(a60, a60, 5, 5, false), 20);
}

TEST(Transition, ConstraintFramesAreFramesOfTheOutput) {
  const Motion a = clip_a(), b = clip_b();
  TransitionRequest r = request(20, TransitionRequest::Placement::kKeep);
  const Motion whole = run_transition(a, b, r, "interp", 0).motions[0];
  // A target inside the transition where interpolation puts the joint: met.
  const int frame = a.num_frames() + 10, joint = a.num_joints() - 1;
  TargetSpec target;
  target.frame = frame;
  target.joint = a.skeleton.names[joint];
  target.position = forward_kinematics(whole).position(frame, joint) / r.length_scale;
  r.constraints.targets.push_back(target);
  const TransitionResult t = run_transition(a, b, r, "interp", 0);
  ASSERT_EQ(t.reports.size(), 1u);
  EXPECT_EQ(t.reports[0].targets.count, 1);
  EXPECT_LT(t.reports[0].targets.max_cm, 1.0);
  EXPECT_TRUE(same_frames(t.motions[0], 0, a, 0, a.num_frames()));
  // One past the output's last frame is out of range.
  r.constraints.targets[0].frame = whole.num_frames();
  EXPECT_THROW(run_transition(a, b, r, "interp", 0), InputError);
}

TEST(Transition, BadRequestsAreInputErrors) {
  const Motion a = clip_a(), b = clip_b();
  auto message = [&](TransitionRequest r, const Motion& x, const Motion& y) {
    try {
      run_transition(x, y, r, "interp", 0);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  TransitionRequest r = request(10);
  r.from_frame = a.num_frames();
  EXPECT_NE(message(r, a, b).find("from_frame"), std::string::npos);
  r.from_frame = 0;  // A would keep one frame
  EXPECT_NE(message(r, a, b).find("from_frame 0 is out of range"), std::string::npos);
  r = request(10);
  r.to_frame = b.num_frames() - 1;
  EXPECT_NE(message(r, a, b).find("to_frame"), std::string::npos);
  r.to_frame = -b.num_frames() - 1;
  EXPECT_NE(message(r, a, b).find("to_frame"), std::string::npos);
  EXPECT_NE(message(request(601), a, b).find("between 1 and 600"), std::string::npos);
  EXPECT_NE(message(request(-1), a, b).find("between 1 and 600"), std::string::npos);
  EXPECT_NE(message(request(10), a.slice(0, 1), b).find("clip A has 1 frame"), std::string::npos);
  EXPECT_NE(message(request(10), a, b.slice(0, 1)).find("clip B has 1 frame"), std::string::npos);
  EXPECT_THROW(run_transition(a, b, request(10), "no-such-method", 0), InputError);
}

// The default method with a (tiny) prior: the model's path, parts exact.
TEST(Transition, DefaultMethodWithThePrior) {
  const Skeleton s = test::small_skeleton();
  const Motion source = test::random_motion(s, 50, 30.0, 11);
  const Motion a = source.slice(0, 20), b = source.slice(25, 50);
  TaskContext ctx;
  ctx.model = test::shared_runtime_of(test::tiny_prior());
  const TransitionResult t = run_transition(a, b, request(8), "", 0, ctx);
  EXPECT_EQ(t.method, default_method(ctx));
  const Motion& out = t.motions[0];
  ASSERT_EQ(out.num_frames(), 20 + 8 + 25);
  EXPECT_TRUE(test::all_finite(out));
  EXPECT_TRUE(same_frames(out, 0, a, 0, 20));
  EXPECT_TRUE(same_frames(out, 28, place_transition_clip(a, b, 19, 0, 8), 0, 25));
}

}  // namespace
}  // namespace mf
