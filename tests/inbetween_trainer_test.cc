// The in-betweener trainer on a tiny synthetic dataset: loss goes down,
// checkpoints resume, best.mfm loads; the real kinds train with tiny sizes.
#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "prior/inbetween/inbetweener.h"
#include "prior/motion/errors.h"
#include "prior/motion/motion_bvh.h"
#include "tests/inbetween_test_model.h"
#include "tests/test_util.h"
#include "training/inbetween_trainer.h"

namespace mf {
namespace {

namespace fs = std::filesystem;

std::string make_data(const std::string& name) {
  std::string dir = test::scratch_dir(name);
  Skeleton s = test::small_skeleton();
  for (int i = 0; i < 14; ++i) {
    Motion m = test::random_motion(s, 20 + 9 * i, 30.0, 300 + i);
    write_motion(dir + "/clip" + std::to_string(i) + ".bvh", m, default_bvh_layout(s));
  }
  return dir;
}

InbetweenTrainingOptions tiny_options(const std::string& data, const std::string& kind) {
  InbetweenTrainingOptions o;
  o.kind = kind;
  o.data = data;
  o.cache_dir = data + "/cache";
  o.out_dir = data + "/run-" + kind;
  o.batch = 4;
  o.epoch_steps = 10;
  o.validation_windows = 8;
  o.min_length = 8;
  o.verbose = false;
  return o;
}

TEST(InbetweenTraining, LossDecreasesCheckpointAndResume) {
  test::register_linear_inbetweener();
  std::string data = make_data("inbetween_training");
  InbetweenTrainingOptions o = tiny_options(data, "test-linear");
  o.hyperparameters = {{"window", 24}};
  o.lr = 1e-2;
  o.max_steps = 60;
  o.max_epochs = 3;
  InbetweenTrainingResult r = train_inbetweener(o);
  EXPECT_EQ(r.epochs, 3);
  EXPECT_EQ(r.steps, 30);
  for (const char* f : {"best.mfm", "last.mfm", "last.optim", "last.state", "log.csv"}) {
    EXPECT_TRUE(fs::exists(o.out_dir + "/" + f)) << f;
  }
  std::vector<double> train = test::log_column(o.out_dir + "/log.csv", "train_loss");
  ASSERT_EQ(train.size(), 3u);
  EXPECT_LT(train[2], 0.95 * train[0]);
  std::vector<double> val = test::log_column(o.out_dir + "/log.csv", "val_score");
  EXPECT_LT(val[2], val[0]);
  EXPECT_EQ(test::log_column(o.out_dir + "/log.csv", "train_linear").size(), 3u);
  EXPECT_GT(test::log_column(o.out_dir + "/log.csv", "train_contact")[0], 0.0);

  auto best = load_inbetweener(r.best_path);
  EXPECT_EQ(best->kind(), "test-linear");
  EXPECT_EQ(best->window(), 24);
  EXPECT_GT(best->stats().pose_std.min().item<float>(), 0.0f);
  EXPECT_FALSE(at::equal(best->stats().pose_std, at::ones_like(best->stats().pose_std)));  // measured

  o.resume = true;
  o.max_epochs = 5;
  InbetweenTrainingResult r2 = train_inbetweener(o);
  EXPECT_EQ(r2.epochs, 5);
  EXPECT_EQ(r2.steps, 50);
  EXPECT_LE(r2.best_validation, r.best_validation);
  EXPECT_EQ(test::log_column(o.out_dir + "/log.csv", "train_loss").size(), 5u);
  // Resuming with other hyperparameters or another kind is refused.
  o.hyperparameters = {{"window", 32}};
  EXPECT_THROW(train_inbetweener(o), InputError);
  o.hyperparameters = {};
  o.kind = kCitlKind;
  EXPECT_THROW(train_inbetweener(o), InputError);

  // --init: a new run starts from the best model's weights and statistics
  // (with a zero learning rate they come out unchanged).
  InbetweenTrainingOptions f = tiny_options(data, "test-linear");
  f.out_dir = data + "/finetune";
  f.init_from = r2.best_path;
  f.lr = 1e-12;
  f.max_epochs = 1;
  train_inbetweener(f);
  auto tuned = load_inbetweener(f.out_dir + "/last.mfm");
  auto from = load_inbetweener(r2.best_path);
  std::vector<at::Tensor> a = from->parameters(), b = tuned->parameters();
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(at::allclose(a[i], b[i], 0.0, 1e-9)) << "parameter " << i;
  EXPECT_TRUE(at::equal(from->stats().pose_std, tuned->stats().pose_std));
  // Another kind or other hyperparameters than the file's are refused, unless
  // they only add parameters (RealKindsTrainAFewSteps: the two-stage gate).
  InbetweenTrainingOptions other = f;
  other.out_dir = data + "/finetune-other";
  other.hyperparameters = {{"window", 32}};
  EXPECT_THROW(train_inbetweener(other), InputError);
  other.hyperparameters = {};
  other.kind = kCitlKind;
  EXPECT_THROW(train_inbetweener(other), InputError);
}

TEST(InbetweenTraining, RealKindsTrainAFewSteps) {
  std::string data = make_data("inbetween_training_kinds");
  for (const std::string kind : {kTwoStageKind, kCitlKind, kKeyframeKind}) {
    InbetweenTrainingOptions o = tiny_options(data, kind);
    o.hyperparameters = {{"width", 16}, {"layers", 1}, {"heads", 2}, {"ffn", 32}, {"window", 32}};
    if (kind == kCitlKind) o.hyperparameters["time_dim"] = 4;
    if (kind == kKeyframeKind) {  // transitions of 5..20 frames after 4 context frames
      o.context = 4;
      o.max_transition = 20;
    }
    o.max_epochs = 2;
    o.epoch_steps = 3;
    InbetweenTrainingResult r = train_inbetweener(o);
    EXPECT_EQ(r.steps, 6) << kind;
    auto m = load_inbetweener(r.best_path);
    EXPECT_EQ(m->kind(), kind);
    EXPECT_EQ(m->window(), 32);
    EXPECT_EQ(test::log_column(o.out_dir + "/log.csv", "val_score").size(), 2u) << kind;
    if (kind != kTwoStageKind) continue;
    // --init with --hp interp_input=1 keeps every trained parameter and adds the gate.
    InbetweenTrainingOptions g = o;
    g.out_dir = data + "/grown-twostage";
    g.init_from = r.best_path;
    g.hyperparameters["interp_input"] = 1;
    g.lr = 1e-12;
    g.max_epochs = 1;
    train_inbetweener(g);
    auto grown = load_inbetweener(g.out_dir + "/last.mfm");
    EXPECT_EQ(grown->hyperparameters().at("interp_input"), 1.0);
    std::map<std::string, at::Tensor> after;
    for (auto& [name, t] : grown->named_parameters()) after[name] = t;
    EXPECT_EQ(after.size(), m->named_parameters().size() + 1);
    for (auto& [name, t] : m->named_parameters()) EXPECT_TRUE(at::allclose(after.at(name), t, 0.0, 1e-9)) << name;
    EXPECT_TRUE(at::equal(grown->stats().pose_std, m->stats().pose_std));
  }
}

TEST(InbetweenTraining, BadOptionsThrow) {
  InbetweenTrainingOptions o;
  o.kind = kCitlKind;
  EXPECT_THROW(train_inbetweener(o), InputError);  // no output directory
  o.out_dir = test::scratch_dir("inbetween_training_bad");
  o.batch = 0;
  EXPECT_THROW(train_inbetweener(o), InputError);
}

}  // namespace
}  // namespace mf
