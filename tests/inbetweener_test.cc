// The shared in-betweener code: pose features, the loss, the model file and
// the factory (with a tiny stand-in model, tests/inbetween_test_model.h).
#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/types.h>

#include "prior/inbetween/inbetweener.h"
#include "prior/model/model_file.h"
#include "prior/motion/errors.h"
#include "prior/motion/kinematics_torch.h"
#include "tests/inbetween_test_model.h"
#include "tests/test_util.h"

namespace mf {
namespace {

struct Sample {
  at::Tensor rot, pos, pose;
};

Sample random_window(const RigInfo& rig, int frames, uint32_t seed) {
  Motion m = test::random_motion(rig.skeleton, frames, 30.0, seed);
  WindowTensors w = window_tensors(m, 0, frames, rig, 0);
  return {w.local_rotations, w.root_positions, pose_features(w.local_rotations, w.root_positions)};
}

std::string error_of(const std::vector<uint8_t>& b) {
  try {
    deserialize_inbetweener(b.data(), b.size(), "x.mfm");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Inbetweener, PoseFeaturesRoundTrip) {
  RigInfo rig = test::tiny_rig();
  const int J = rig.num_joints();
  Sample s = random_window(rig, 12, 3);
  ASSERT_EQ(s.pose.sizes(), (at::IntArrayRef{1, 12, J * 6 + 3}));
  // Layout: joint j's 6D = first two columns, column-major; root position last.
  EXPECT_TRUE(at::allclose(s.pose.select(-1, 6 * 2 + 1), s.rot.select(2, 2).select(-1, 0).select(-1, 1)));
  EXPECT_TRUE(at::allclose(s.pose.select(-1, 6 * 2 + 3), s.rot.select(2, 2).select(-1, 1).select(-1, 0)));
  at::Tensor rot, pos;
  split_pose_features(s.pose, J, &rot, &pos);
  EXPECT_LT((rot - s.rot).abs().max().item<float>(), 1e-5);
  EXPECT_TRUE(at::equal(pos, s.pos));
  // Gram-Schmidt re-orthonormalises a perturbed 6D.
  split_pose_features(s.pose + 0.05 * at::randn_like(s.pose), J, &rot, nullptr);
  EXPECT_LT((at::matmul(rot, rot.transpose(-1, -2)) - at::eye(3)).abs().max().item<float>(), 1e-4);
  EXPECT_THROW(split_pose_features(s.pose, J + 1, &rot, &pos), InputError);
}

TEST(Inbetweener, KnownChannelMask) {
  at::Tensor known = at::tensor({1.f, 0.f, 1.f, 0.f}).view({1, 1, 4});  // J = 3, root position unknown
  at::Tensor m = known_channel_mask(known, 3);
  ASSERT_EQ(m.size(-1), 21);
  EXPECT_EQ(m.sum().item<float>(), 12.f);
  EXPECT_EQ(m[0][0][6].item<float>(), 0.f);
  EXPECT_EQ(m[0][0][12].item<float>(), 1.f);
  EXPECT_EQ(m[0][0][20].item<float>(), 0.f);
}

TEST(Inbetweener, LossTermsUnitsAndMasking) {
  test::register_linear_inbetweener();
  RigInfo rig = test::tiny_rig();
  auto model = make_inbetweener("test-linear", {}, rig);
  Sample s = random_window(rig, 10, 4);
  at::Tensor valid = at::ones({1, 10});
  InbetweenLossParts parts;
  EXPECT_LT(inbetween_pose_loss(*model, s.pose, s.pose, valid, &parts).item<float>(), 1e-6);
  // Moving the root by 10 cm: root and FK position terms are 0.1 m, rotation 0.
  at::Tensor moved = s.pose.clone();
  moved.narrow(-1, model->pose_size() - 3, 1).add_(0.1);
  float total = inbetween_pose_loss(*model, moved, s.pose, valid, &parts).item<float>();
  EXPECT_NEAR(parts.root.item<float>(), 0.1f / 3, 1e-5);
  EXPECT_NEAR(parts.position.item<float>(), 0.1f / 3, 1e-5);
  EXPECT_NEAR(parts.rotation.item<float>(), 0.f, 1e-6);
  EXPECT_NEAR(total, 0.2f / 3, 1e-5);
  // Invalid frames do not count; the average is over valid frames.
  at::Tensor half = at::zeros({1, 10});
  half.narrow(1, 0, 5).fill_(1);
  at::Tensor wrong_tail = s.pose.clone();
  wrong_tail.narrow(1, 5, 5).add_(1.0);
  EXPECT_LT(inbetween_pose_loss(*model, wrong_tail, s.pose, half).item<float>(), 1e-6);
  // Rotations: gradients reach the prediction through the 6D and FK terms.
  at::Tensor p = (s.pose + 0.1 * at::randn_like(s.pose)).set_requires_grad(true);
  at::Tensor loss = inbetween_pose_loss(*model, p, s.pose, valid, &parts);
  loss.backward();
  EXPECT_GT(parts.rotation.item<float>(), 0.f);
  EXPECT_GT(parts.position.item<float>(), 0.f);
  ASSERT_TRUE(p.grad().defined());
  EXPECT_TRUE(at::isfinite(p.grad()).all().item<bool>());
  EXPECT_THROW(inbetween_pose_loss(*model, s.pose.narrow(-1, 0, 6), s.pose, valid), InputError);
}

TEST(Inbetweener, BaseMembers) {
  test::register_linear_inbetweener();
  RigInfo rig = test::tiny_rig();
  auto model = make_inbetweener("test-linear", {{"window", 48}}, rig);
  EXPECT_EQ(model->window(), 48);
  EXPECT_EQ(model->fps(), 30.0);
  const int64_t D = rig.num_joints() * 6 + 3;
  EXPECT_EQ(model->pose_size(), D);
  EXPECT_EQ(model->num_parameters(), D * (D + rig.num_joints() + 1) + D + rig.num_feet() * (D + rig.num_joints() + 2));
  EXPECT_EQ(model->parameters().size(), 4u);
  EXPECT_TRUE(at::equal(model->stats().pose_std, at::ones({D})));
  model->set_requires_grad(false);
  for (auto& t : model->parameters()) EXPECT_FALSE(t.requires_grad());
  EXPECT_THROW(make_inbetweener("no-such-kind", {}, rig), InputError);
  EXPECT_THROW(register_inbetweener_kind(kTwoStageKind, {}), InputError);
}

class InbetweenerFile : public ::testing::Test {
 protected:
  void SetUp() override {
    test::register_linear_inbetweener();
    at::manual_seed(0);
    rig_ = test::tiny_rig();
    model_ = make_inbetweener("test-linear", {{"window", 40}}, rig_);
    model_->stats().pose_mean.fill_(0.25);
    model_->stats().pose_std.fill_(2.0);
    dir_ = test::scratch_dir("inbetweener_file");
    bytes_ = serialize_inbetweener(*model_);
  }
  RigInfo rig_;
  std::unique_ptr<InbetweenModel> model_;
  std::string dir_;
  std::vector<uint8_t> bytes_;
};

TEST_F(InbetweenerFile, RoundTripGivesTheSameOutputs) {
  save_inbetweener(*model_, dir_ + "/m.mfm");
  auto b = load_inbetweener(dir_ + "/m.mfm");
  EXPECT_EQ(b->kind(), "test-linear");
  EXPECT_EQ(b->hyperparameters(), model_->hyperparameters());
  EXPECT_EQ(b->window(), 40);
  EXPECT_TRUE(b->rig().skeleton.same_as(rig_.skeleton));
  EXPECT_EQ(b->rig().foot_joints, rig_.foot_joints);
  EXPECT_TRUE(at::equal(b->stats().pose_mean, model_->stats().pose_mean));
  Sample s = random_window(rig_, 8, 5);
  InbetweenBatch batch{s.pose, at::ones({1, 8, rig_.num_joints() + 1}), at::ones({1, 8})};
  EXPECT_TRUE(at::allclose(b->forward(batch).stages[0], model_->forward(batch).stages[0]));
  EXPECT_TRUE(at::allclose(b->forward(batch).contact_logits, model_->forward(batch).contact_logits));
}

TEST_F(InbetweenerFile, ErrorsSayWhatIsWrong) {
  std::vector<uint8_t> b = bytes_;
  b[0] = 'X';
  EXPECT_NE(error_of(b).find("not a motionfield model file"), std::string::npos);
  b = bytes_;
  b.resize(b.size() - 20);
  EXPECT_NE(error_of(b).find("truncated"), std::string::npos);
  b = bytes_;
  b[b.size() / 2] ^= 0x5a;
  EXPECT_NE(error_of(b).find("checksum"), std::string::npos);
  EXPECT_THROW(load_inbetweener(dir_ + "/missing.mfm"), InputError);
  // A prior file is not an in-betweener and vice versa.
  NemfModel prior(test::tiny_nemf_config(), rig_);
  std::vector<uint8_t> nemf = serialize_nemf(prior);
  std::string e = error_of(nemf);
  EXPECT_NE(e.find("wrong kind of model"), std::string::npos) << e;
  EXPECT_NE(e.find("'nemf'"), std::string::npos) << e;
  try {
    deserialize_nemf(bytes_.data(), bytes_.size(), "y.mfm");
    ADD_FAILURE() << "an in-betweener loaded as a prior";
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find("wrong kind of model"), std::string::npos);
  }
  // Misshapen weights: the same kind with other sizes.
  auto other = make_inbetweener("test-linear", {{"window", 40}, {"contacts", 0}}, rig_);
  std::vector<uint8_t> fewer = serialize_inbetweener(*other);
  auto hp = other->hyperparameters();
  hp["contacts"] = 1;  // claims a contact head the file lacks
  std::vector<std::pair<std::string, at::Tensor>> tensors = {{"stats.pose_mean", other->stats().pose_mean},
                                                             {"stats.pose_std", other->stats().pose_std}};
  for (auto& t : other->named_parameters()) tensors.push_back(t);
  std::vector<uint8_t> lacking = serialize_model_file("test-linear", hp, rig_, tensors);
  EXPECT_NE(error_of(lacking).find("lacks tensor 'contact.weight'"), std::string::npos) << error_of(lacking);
  tensors.push_back({"extra", at::zeros({2})});
  hp["contacts"] = 0;
  std::vector<uint8_t> extra = serialize_model_file("test-linear", hp, rig_, tensors);
  EXPECT_NE(error_of(extra).find("unexpected tensor 'extra'"), std::string::npos) << error_of(extra);
  hp.erase("window");
  tensors.pop_back();
  std::vector<uint8_t> no_window = serialize_model_file("test-linear", hp, rig_, tensors);
  EXPECT_NE(error_of(no_window).find("'window'"), std::string::npos) << error_of(no_window);
  EXPECT_EQ(error_of(fewer), "");
}

}  // namespace
}  // namespace mf
