// The transformer in-betweeners on Eigen (prior/runtime/inbetween_runtime.h)
// against the libtorch networks (prior/inbetween/): the shipped model of each
// kind, both loaded from its file, and small random models of the same kinds
// (random weights and statistics, written to bytes by the libtorch code and
// read by the runtime), on random windows with random known masks and
// padding, and on a real window (the sample walk on the model's rig, context
// frames, a target, a partial and a root-only key). Every stage's output, the
// contact logits and the keyframe outputs must agree within 1e-5 relative to
// the largest libtorch value (issue 56's bound); the worst difference per
// kind is printed.
#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "prior/inbetween/inbetweener.h"
#include "prior/model/model_file.h"
#include "prior/motion/errors.h"
#include "prior/runtime/inbetween_runtime.h"
#include "prior/util/threads.h"
#include "tasks/transformer/inbetweener_files.h"
#include "tasks/transformer/inbetweener_fill.h"
#include "tests/runtime_test_util.h"
#include "tests/test_util.h"

namespace mf {
namespace {

using runtime::InbetweenerRuntime;
using runtime::InbetweenResult;
using runtime::InbetweenWindow;
using test::MatrixRXf;
using test::relative_difference;
using test::to_matrix;

// One window both ways: the libtorch batch (B = 1) and the runtime's window.
struct Case {
  InbetweenBatch batch;
  InbetweenWindow window;
};

Case make_case(const at::Tensor& pose, const at::Tensor& known, const at::Tensor& valid, const at::Tensor& trajectory) {
  Case c;
  c.batch = {pose.unsqueeze(0), known.unsqueeze(0), valid.unsqueeze(0), at::Tensor()};
  c.window.pose = to_matrix(pose);
  c.window.known = to_matrix(known);
  c.window.valid = test::to_vector(valid);
  if (trajectory.defined()) {
    c.batch.trajectory = trajectory.unsqueeze(0);
    c.window.trajectory = to_matrix(trajectory);
  }
  return c;
}

// T frames of which the first `valid_frames` are valid: frame 0 fully known,
// a few full keys, partial keys (random joints, with or without the root
// position) and root-only keys; random values everywhere, the unknown ones
// included (both sides must ignore them).
Case random_case(const InbetweenModel& model, int T, int valid_frames, uint32_t seed, bool with_trajectory) {
  std::mt19937 rng(seed);
  const int64_t J = model.rig().num_joints(), D = model.pose_size();
  at::manual_seed(seed);
  at::Tensor pose = at::randn({T, D});
  at::Tensor known = at::zeros({T, J + 1}), valid = at::zeros({T});
  valid.narrow(0, 0, valid_frames).fill_(1.0);
  known[0].fill_(1.0);
  std::uniform_int_distribution<int> frame(1, valid_frames - 1), joint(0, static_cast<int>(J));
  for (int k = 0; k < 2; ++k) known[frame(rng)].fill_(1.0);
  for (int k = 0; k < 3; ++k) {
    const int t = frame(rng);
    for (int n = 0; n < 3; ++n) known[t][joint(rng)] = 1.0;
  }
  known[frame(rng)][J] = 1.0;
  known[T - 1].fill_(1.0);  // on padding when valid_frames < T: must not count
  at::Tensor trajectory;
  if (with_trajectory) {
    trajectory = at::randn({T, 4});
    trajectory.narrow(1, 2, 2).div_(trajectory.narrow(1, 2, 2).norm(2, -1, true));
  }
  return make_case(pose, known, valid, trajectory);
}

// The sample walk on the model's rig, its first T frames (T <= 61) in a
// window of T + padding frames: 10 context frames and the target known, a
// partial key (the root rotation and two joints) and a root-only key between.
Case real_case(const InbetweenModel& model, int T, int padding) {
  const Motion& walk = test::walk_on_model_rig();
  const WindowTensors w = window_tensors(walk, 0, T, model.rig(), 0);
  const int64_t J = model.rig().num_joints(), D = model.pose_size();
  at::Tensor pose = at::zeros({T + padding, D}), known = at::zeros({T + padding, J + 1});
  at::Tensor valid = at::zeros({T + padding});
  pose.narrow(0, 0, T).copy_(pose_features(w.local_rotations, w.root_positions)[0]);
  valid.narrow(0, 0, T).fill_(1.0);
  known.narrow(0, 0, 10).fill_(1.0);
  known[T - 1].fill_(1.0);
  for (int64_t j : {int64_t{0}, J / 2, J - 1}) known[T / 2][j] = 1.0;
  known[T / 2 + 5][J] = 1.0;
  pose = pose * known_channel_mask(known, static_cast<int>(J));
  return make_case(pose, known, valid, at::Tensor());
}

// Runs both on `c` and returns the worst relative difference over every
// output, each expected within the bound.
double compare(const InbetweenModel& model, const InbetweenerRuntime& rt, const Case& c, const std::string& label) {
  ScopedComputeThreads one_thread(1);
  at::NoGradGuard no_grad;
  const InbetweenOutput expected = model.forward(c.batch);
  InbetweenResult got;
  rt.forward(c.window, &got);
  std::vector<std::pair<std::string, double>> diffs;
  EXPECT_EQ(got.stages.size(), expected.stages.size());
  for (size_t s = 0; s < std::min(got.stages.size(), expected.stages.size()); ++s) {
    diffs.push_back({model.stage_names()[s], relative_difference(got.stages[s], to_matrix(expected.stages[s][0]))});
  }
  EXPECT_EQ(got.contact_logits.size() > 0, expected.contact_logits.defined());
  if (expected.contact_logits.defined()) {
    diffs.push_back({"contacts", relative_difference(got.contact_logits, to_matrix(expected.contact_logits[0]))});
  }
  if (expected.keyframe_logits.defined()) {
    diffs.push_back({"keyframe poses", relative_difference(got.keyframe_poses, to_matrix(expected.keyframe_poses[0]))});
    diffs.push_back({"keyframe logits", relative_difference(got.keyframe_logits.transpose(),
                                                            to_matrix(expected.keyframe_logits))});
    EXPECT_EQ(relative_difference(got.keyframes.transpose(), to_matrix(expected.keyframes)), 0.0) << label;
  }
  double worst = 0.0;
  std::printf("%s:", label.c_str());
  for (const auto& [name, d] : diffs) {
    EXPECT_LT(d, test::kOutputTolerance) << label << ", " << name;
    worst = std::max(worst, d);
    std::printf(" %s %.2e", name.c_str(), d);
  }
  std::printf("\n");
  return worst;
}

// A small random model of `kind` on the tiny rig with random statistics.
std::unique_ptr<InbetweenModel> small_model(const std::string& kind, const std::map<std::string, double>& hp,
                                            uint64_t seed) {
  at::manual_seed(seed);
  auto model = make_inbetweener(kind, hp, test::tiny_rig());
  const int64_t D = model->pose_size();
  model->stats().pose_mean = at::randn({D}) * 0.1;
  model->stats().pose_std = at::rand({D}) + 0.5;
  model->train(false);
  return model;
}

// The runtime of `model`'s bytes.
std::unique_ptr<const InbetweenerRuntime> runtime_of(const InbetweenModel& model) {
  const std::vector<uint8_t> bytes = serialize_inbetweener(model);
  return runtime::inbetweener_runtime_from_bytes(bytes.data(), bytes.size(), "small " + model.kind());
}

// Random windows (full, padded, short) and the real window on `model`.
double compare_windows(const InbetweenModel& model, const InbetweenerRuntime& rt, const std::string& name,
                       bool with_trajectory) {
  const int W = model.window();
  double worst = 0.0;
  const std::vector<std::pair<int, int>> sizes = {{W, W}, {W, W - 7}, {std::min(W, 23), std::min(W, 23) - 3}};
  for (size_t i = 0; i < sizes.size(); ++i) {
    const Case c = random_case(model, sizes[i].first, sizes[i].second, 100 + i, false);
    worst = std::max(worst, compare(model, rt, c, name + " random T=" + std::to_string(sizes[i].first)));
    if (with_trajectory) {
      const Case t = random_case(model, sizes[i].first, sizes[i].second, 200 + i, true);
      worst = std::max(worst, compare(model, rt, t, name + " random+trajectory T=" + std::to_string(sizes[i].first)));
    }
  }
  return worst;
}

double compare_real_windows(const InbetweenModel& model, const InbetweenerRuntime& rt, const std::string& name) {
  const int T = std::min(61, model.window());
  double worst = compare(model, rt, real_case(model, T, 0), name + " walk");
  const int padded = std::min(T, model.window() - 8);
  return std::max(worst, compare(model, rt, real_case(model, padded, 8), name + " walk padded"));
}

void expect_shipped_agrees(const std::string& file, bool with_trajectory) {
  const std::string path = std::string(MF_SOURCE_DIR) + "/models/" + file;
  const std::unique_ptr<InbetweenModel> model = load_inbetweener(path);
  model->set_requires_grad(false);
  const std::unique_ptr<const InbetweenerRuntime> rt = runtime::load_inbetweener_runtime(path);
  EXPECT_EQ(rt->kind(), model->kind());
  EXPECT_EQ(rt->stage_names(), model->stage_names());
  EXPECT_EQ(rt->window(), model->window());
  const double worst = std::max(compare_windows(*model, *rt, file, with_trajectory),
                                compare_real_windows(*model, *rt, file));
  std::printf("%s: worst %.2e\n", file.c_str(), worst);
}

void expect_small_agrees(const std::string& kind, const std::map<std::string, double>& hp,
                         const std::map<std::string, float>& set_parameters, bool with_trajectory) {
  std::unique_ptr<InbetweenModel> model = small_model(kind, hp, 7);
  {
    at::NoGradGuard no_grad;
    size_t set = 0;
    for (auto& [name, p] : model->named_parameters()) {
      auto it = set_parameters.find(name);
      if (it != set_parameters.end()) p.fill_(it->second), ++set;
    }
    ASSERT_EQ(set, set_parameters.size());
  }
  const auto rt = runtime_of(*model);
  const double worst = compare_windows(*model, *rt, "small " + kind, with_trajectory);
  std::printf("small %s: worst %.2e\n", kind.c_str(), worst);
}

TEST(RuntimeInbetweenEquivalence, ShippedTwoStage) { expect_shipped_agrees("motionfield-twostage.mfm", false); }

TEST(RuntimeInbetweenEquivalence, SmallTwoStage) {
  expect_small_agrees(kTwoStageKind, {{"width", 16}, {"layers", 2}, {"heads", 2}, {"ffn", 24}, {"window", 40}}, {},
                      false);
}

// interp_input: the gate opened (a new model's is 0, which would hide the context stage).
TEST(RuntimeInbetweenEquivalence, SmallTwoStageOnInterpolatedInput) {
  expect_small_agrees(kTwoStageKind,
                      {{"width", 16}, {"layers", 1}, {"heads", 4}, {"ffn", 8}, {"window", 40}, {"interp_input", 1}},
                      {{"context.gate", 0.07f}}, false);
}

TEST(RuntimeInbetweenEquivalence, ShippedCitl) { expect_shipped_agrees("motionfield-citl.mfm", false); }

TEST(RuntimeInbetweenEquivalence, SmallCitl) {
  expect_small_agrees(kCitlKind, {{"width", 16}, {"layers", 2}, {"heads", 2}, {"ffn", 24}, {"time_dim", 6}, {"window", 40}},
                      {}, false);
}

TEST(RuntimeInbetweenEquivalence, ShippedKeyframe) { expect_shipped_agrees("motionfield-keyframe.mfm", true); }

TEST(RuntimeInbetweenEquivalence, SmallKeyframe) {
  expect_small_agrees(kKeyframeKind,
                      {{"width", 16}, {"layers", 2}, {"heads", 2}, {"ffn", 24}, {"window", 48}, {"min_spacing", 3},
                       {"max_spacing", 8}},
                      {}, true);
}

// No known value at all: every key of the context stage (and CITL's) masked.
// The keyframe kind gets a random trajectory: without one every frame's
// input is alike, the score logits tie to float rounding, and which of the
// tied frames is picked is rounding's choice (on both sides).
TEST(RuntimeInbetweenEquivalence, WindowsWithoutKnownValues) {
  const std::vector<std::pair<std::string, std::map<std::string, double>>> kinds = {
      {kTwoStageKind, {{"width", 16}, {"layers", 1}, {"heads", 2}, {"window", 24}}},
      {kCitlKind, {{"width", 16}, {"layers", 1}, {"heads", 2}, {"time_dim", 4}, {"window", 24}}},
      {kKeyframeKind, {{"width", 16}, {"layers", 1}, {"heads", 2}, {"window", 24}, {"min_spacing", 2}, {"max_spacing", 5}}}};
  for (const auto& [kind, hp] : kinds) {
    std::unique_ptr<InbetweenModel> model = small_model(kind, hp, 5);
    const auto rt = runtime_of(*model);
    const int64_t J = model->rig().num_joints();
    at::manual_seed(5);
    at::Tensor valid = at::ones({24});
    valid.narrow(0, 20, 4).zero_();
    at::Tensor trajectory;
    if (kind == kKeyframeKind) {
      trajectory = at::randn({24, 4});
      trajectory.narrow(1, 2, 2).div_(trajectory.narrow(1, 2, 2).norm(2, -1, true));
    }
    const Case c = make_case(at::randn({24, model->pose_size()}), at::zeros({24, J + 1}), valid, trajectory);
    compare(*model, *rt, c, "small " + kind + " without known values");
  }
}

TEST(RuntimeInbetweenEquivalence, FilesWithOtherTensorsAreRefused) {
  std::unique_ptr<InbetweenModel> model = small_model(kTwoStageKind, {{"width", 8}, {"layers", 1}, {"window", 16}}, 1);
  std::vector<std::pair<std::string, at::Tensor>> tensors = {{"stats.pose_mean", model->stats().pose_mean},
                                                             {"stats.pose_std", model->stats().pose_std}};
  for (auto& named : model->named_parameters()) tensors.push_back(named);
  EXPECT_THROW(runtime::load_inbetweener_runtime(test::shipped_model_path()), InputError);  // the prior's file
  tensors.push_back({"context.extra", at::zeros({2})});
  const std::vector<uint8_t> bytes = serialize_model_file(model->kind(), model->hyperparameters(), model->rig(), tensors);
  EXPECT_THROW(runtime::inbetweener_runtime_from_bytes(bytes.data(), bytes.size(), "extra"), InputError);
  tensors.pop_back();
  tensors.pop_back();  // the last parameter missing
  const std::vector<uint8_t> fewer = serialize_model_file(model->kind(), model->hyperparameters(), model->rig(), tensors);
  EXPECT_THROW(runtime::inbetweener_runtime_from_bytes(fewer.data(), fewer.size(), "fewer"), InputError);
}

TEST(RuntimeInbetweenEquivalence, WindowsOfTheWrongShapeAreRefused) {
  std::unique_ptr<InbetweenModel> model = small_model(kTwoStageKind, {{"width", 8}, {"layers", 1}, {"window", 16}}, 1);
  const auto rt = runtime_of(*model);
  Case c = random_case(*model, 16, 16, 1, false);
  InbetweenResult out;
  InbetweenWindow longer = c.window;
  longer.pose.conservativeResize(17, Eigen::NoChange);
  EXPECT_THROW(rt->forward(longer, &out), InputError);
  InbetweenWindow short_known = c.window;
  short_known.known.conservativeResize(15, Eigen::NoChange);
  EXPECT_THROW(rt->forward(short_known, &out), InputError);
}

}  // namespace
}  // namespace mf
