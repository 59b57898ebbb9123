#include "prior/inbetween/two_stage.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/optim/adam.h>

#include "prior/motion/errors.h"
#include "tests/test_util.h"

namespace mf {
namespace {

constexpr int kWindow = 16;

std::map<std::string, double> tiny_hyperparameters() {
  return {{"width", 32}, {"layers", 1}, {"heads", 2}, {"ffn", 48}, {"window", kWindow}, {"fps", 30}};
}

std::unique_ptr<InbetweenModel> tiny_two_stage(uint64_t seed = 0) {
  at::manual_seed(seed);
  auto model = make_two_stage(tiny_hyperparameters(), test::tiny_rig());
  const int64_t D = model->pose_size();
  model->stats().pose_mean = at::randn({D}) * 0.1;
  model->stats().pose_std = at::rand({D}) + 0.5;
  return model;
}

// Two windows: sample 0 uses all 16 frames with full keys at 0, 5 and 15;
// sample 1 has 10 valid frames, full keys at 0 and 9, a partial key at 3 (two
// joints, no root position) and a root-position-only key at 6. Unknown entries
// of pose are zero.
InbetweenBatch two_windows(const InbetweenModel& model) {
  const int64_t J = model.rig().num_joints(), D = model.pose_size();
  InbetweenBatch b;
  b.known = at::zeros({2, kWindow, J + 1});
  b.valid = at::zeros({2, kWindow});
  for (int t : {0, 5, 15}) b.known[0][t].fill_(1.0);
  for (int t : {0, 9}) b.known[1][t].fill_(1.0);
  b.known[1][3][1] = 1.0;
  b.known[1][3][2] = 1.0;
  b.known[1][6][J] = 1.0;
  b.valid[0].fill_(1.0);
  b.valid[1].narrow(0, 0, 10).fill_(1.0);
  b.pose = at::randn({2, kWindow, D}) * known_channel_mask(b.known, static_cast<int>(J));
  return b;
}

InbetweenOutput run(const InbetweenModel& model, const InbetweenBatch& batch) {
  InbetweenOutput out = model.forward(batch);
  EXPECT_EQ(out.stages.size(), 2u);
  return out;
}

TEST(TwoStage, ShapesAndKind) {
  auto model = tiny_two_stage();
  EXPECT_EQ(model->kind(), kTwoStageKind);
  EXPECT_EQ(model->stage_names(), (std::vector<std::string>{"context", "detail"}));
  EXPECT_EQ(model->window(), kWindow);
  EXPECT_EQ(model->fps(), 30.0);
  ASSERT_GT(model->rig().num_feet(), 0);
  InbetweenBatch b = two_windows(*model);
  InbetweenOutput out = run(*model, b);
  ASSERT_EQ(out.stages.size(), 2u);
  for (const at::Tensor& s : out.stages) {
    EXPECT_EQ(s.sizes(), (at::IntArrayRef{2, kWindow, model->pose_size()}));
    EXPECT_TRUE(at::isfinite(s).all().item<bool>());
  }
  EXPECT_EQ(out.contact_logits.sizes(), (at::IntArrayRef{2, kWindow, model->rig().num_feet()}));
  // Shorter windows than `window` are accepted; longer ones and bad shapes are not.
  InbetweenBatch shorter{b.pose.narrow(1, 0, 6), b.known.narrow(1, 0, 6), b.valid.narrow(1, 0, 6)};
  EXPECT_EQ(run(*model, shorter).stages.back().size(1), 6);
  InbetweenBatch one{b.pose.narrow(1, 0, 1), b.known.narrow(1, 0, 1), b.valid.narrow(1, 0, 1)};
  EXPECT_TRUE(at::isfinite(run(*model, one).stages.back()).all().item<bool>());
  InbetweenBatch longer{at::cat({b.pose, b.pose}, 1), at::cat({b.known, b.known}, 1), at::cat({b.valid, b.valid}, 1)};
  EXPECT_THROW(model->forward(longer), InputError);
  EXPECT_THROW(model->forward(InbetweenBatch{b.pose, b.known.narrow(-1, 0, 3), b.valid}), InputError);
  EXPECT_THROW(model->forward(InbetweenBatch{b.pose.narrow(-1, 0, 7), b.known, b.valid}), InputError);
  EXPECT_THROW(model->forward(InbetweenBatch{b.pose, b.known, at::Tensor()}), InputError);
}

TEST(TwoStage, UnknownValuesDoNotChangeTheOutput) {
  auto model = tiny_two_stage(1);
  InbetweenBatch b = two_windows(*model);
  InbetweenOutput reference = run(*model, b);
  at::Tensor mask = known_channel_mask(b.known, model->rig().num_joints());
  InbetweenBatch perturbed = b;
  perturbed.pose = b.pose + at::randn(b.pose.sizes()) * 10.0 * (1.0 - mask);
  InbetweenOutput out = run(*model, perturbed);
  for (size_t s = 0; s < 2; ++s) EXPECT_TRUE(at::equal(out.stages[s], reference.stages[s])) << s;
  EXPECT_TRUE(at::equal(out.contact_logits, reference.contact_logits));
}

TEST(TwoStage, KnownValuesDoChangeTheOutput) {
  auto model = tiny_two_stage(2);
  InbetweenBatch b = two_windows(*model);
  at::Tensor reference = run(*model, b).stages.back();
  InbetweenBatch changed = b;
  changed.pose = b.pose.clone();
  changed.pose[0][5].mul_(-1.0);  // a full key in the middle of sample 0
  at::Tensor out = run(*model, changed).stages.back();
  EXPECT_FALSE(at::allclose(out[0], reference[0]));
  EXPECT_TRUE(at::allclose(out[1], reference[1], 1e-5, 1e-6));  // samples are independent
}

TEST(TwoStage, PaddingFramesDoNotChangeValidFrames) {
  auto model = tiny_two_stage(3);
  InbetweenBatch b = two_windows(*model);
  InbetweenOutput reference = run(*model, b);
  // Garbage in the padding of sample 1: values, known flags, everything.
  InbetweenBatch garbage = b;
  garbage.pose = b.pose.clone();
  garbage.known = b.known.clone();
  garbage.pose[1].narrow(0, 10, kWindow - 10).normal_(0.0, 5.0);
  garbage.known[1].narrow(0, 10, kWindow - 10).fill_(1.0);
  InbetweenOutput out = run(*model, garbage);
  for (size_t s = 0; s < 2; ++s) {
    EXPECT_TRUE(at::allclose(out.stages[s][0], reference.stages[s][0], 1e-5, 1e-6)) << s;
    EXPECT_TRUE(at::allclose(out.stages[s][1].narrow(0, 0, 10), reference.stages[s][1].narrow(0, 0, 10), 1e-5, 1e-6))
        << s;
  }
  EXPECT_TRUE(at::allclose(out.contact_logits[1].narrow(0, 0, 10), reference.contact_logits[1].narrow(0, 0, 10),
                           1e-5, 1e-6));
  // The same window alone, unpadded, gives the same valid frames.
  InbetweenBatch alone{b.pose.narrow(0, 1, 1).narrow(1, 0, 10), b.known.narrow(0, 1, 1).narrow(1, 0, 10),
                       b.valid.narrow(0, 1, 1).narrow(1, 0, 10)};
  InbetweenOutput single = run(*model, alone);
  for (size_t s = 0; s < 2; ++s) {
    EXPECT_TRUE(at::allclose(single.stages[s][0], reference.stages[s][1].narrow(0, 0, 10), 1e-4, 1e-5)) << s;
  }
}

TEST(TwoStage, ArbitraryKeySetsIncludingNone) {
  auto model = tiny_two_stage(4);
  const int64_t J = model->rig().num_joints(), D = model->pose_size();
  InbetweenBatch b;
  b.known = at::zeros({3, kWindow, J + 1});
  b.known[0][0].fill_(1.0);                  // one key
  b.known[1].narrow(0, 0, 12).fill_(1.0);    // dense context, then a gap to the end
  b.known[2][7].narrow(0, 0, 1).fill_(1.0);  // only the root rotation of frame 7
  b.valid = at::ones({3, kWindow});
  b.pose = at::randn({3, kWindow, D}) * known_channel_mask(b.known, static_cast<int>(J));
  EXPECT_TRUE(at::isfinite(run(*model, b).stages.back()).all().item<bool>());
  b.known.zero_();  // no key at all: still finite (no NaN from fully masked rows)
  b.pose.zero_();
  EXPECT_TRUE(at::isfinite(run(*model, b).stages.back()).all().item<bool>());
}

TEST(TwoStage, GradientsReachEveryParameter) {
  auto model = tiny_two_stage(5);
  model->train(true);
  InbetweenBatch b = two_windows(*model);
  InbetweenOutput out = run(*model, b);
  (out.stages[0].pow(2).sum() + out.stages[1].pow(2).sum() + out.contact_logits.pow(2).sum()).backward();
  for (const auto& [name, p] : model->named_parameters()) {
    ASSERT_TRUE(p.grad().defined()) << name;
    EXPECT_GT(p.grad().abs().sum().item<float>(), 0.0f) << name;
  }
}

TEST(TwoStage, HyperparametersRoundTrip) {
  auto defaults = make_two_stage({}, test::tiny_rig());
  std::map<std::string, double> expected = {{"width", 64}, {"layers", 2},   {"heads", 4},
                                            {"ffn", 128},  {"window", 128}, {"fps", 30}};
  EXPECT_EQ(defaults->hyperparameters(), expected);
  auto model = tiny_two_stage();
  auto copy = make_two_stage(model->hyperparameters(), model->rig());
  EXPECT_EQ(copy->hyperparameters(), model->hyperparameters());
  EXPECT_EQ(copy->describe(), model->describe());
  EXPECT_NE(model->describe().find("context 1x32"), std::string::npos) << model->describe();
  auto a = model->named_parameters(), c = copy->named_parameters();
  ASSERT_EQ(a.size(), c.size());
  bool found_query = false;
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].first, c[i].first);
    EXPECT_EQ(a[i].second.sizes(), c[i].second.sizes()) << a[i].first;
    found_query = found_query || a[i].first == "context.layers.0.attn.q.weight";
  }
  EXPECT_TRUE(found_query);
  EXPECT_EQ(a.front().first, "context.input.fc1.weight");
  auto factory = make_inbetweener(kTwoStageKind, model->hyperparameters(), model->rig());
  EXPECT_EQ(factory->kind(), kTwoStageKind);
  EXPECT_EQ(factory->num_parameters(), model->num_parameters());
}

TEST(TwoStage, ModelFileRoundTripGivesTheSameOutputs) {
  auto model = tiny_two_stage(7);
  model->stats().pose_std[3] = 0.0;  // a constant channel stays finite
  InbetweenBatch b = two_windows(*model);
  InbetweenOutput reference = model->forward(b);
  EXPECT_TRUE(at::isfinite(reference.stages.back()).all().item<bool>());
  std::vector<uint8_t> bytes = serialize_inbetweener(*model);
  auto loaded = deserialize_inbetweener(bytes.data(), bytes.size(), "memory");
  EXPECT_EQ(loaded->kind(), kTwoStageKind);
  EXPECT_EQ(loaded->hyperparameters(), model->hyperparameters());
  InbetweenOutput out = loaded->forward(b);
  for (size_t s = 0; s < 2; ++s) EXPECT_TRUE(at::equal(out.stages[s], reference.stages[s])) << s;
  EXPECT_TRUE(at::equal(out.contact_logits, reference.contact_logits));
}

TEST(TwoStage, BadHyperparametersThrow) {
  RigInfo rig = test::tiny_rig();
  auto with = [](const std::string& key, double v) {
    auto h = tiny_hyperparameters();
    h[key] = v;
    return h;
  };
  EXPECT_THROW(make_two_stage(with("heads", 3), rig), InputError);  // does not divide 32
  EXPECT_THROW(make_two_stage(with("heads", 0), rig), InputError);
  EXPECT_THROW(make_two_stage(with("width", 0), rig), InputError);
  EXPECT_THROW(make_two_stage(with("layers", 1.5), rig), InputError);
  EXPECT_THROW(make_two_stage(with("layers", 0), rig), InputError);
  EXPECT_THROW(make_two_stage(with("ffn", -4), rig), InputError);
  EXPECT_THROW(make_two_stage(with("window", 1), rig), InputError);
  EXPECT_THROW(make_two_stage(with("fps", -30), rig), InputError);
  EXPECT_THROW(make_two_stage(with("fps", std::nan("")), rig), InputError);
  EXPECT_THROW(make_two_stage(with("dropout", 0.1), rig), InputError);  // unknown key
  EXPECT_NO_THROW(make_two_stage(with("heads", 4), rig));
}

TEST(TwoStage, OverfitsOneBatch) {
  auto model = tiny_two_stage(6);
  model->train(true);
  InbetweenBatch b = two_windows(*model);
  at::Tensor target = at::randn(b.pose.sizes()) * 0.5;
  at::Tensor mask = known_channel_mask(b.known, model->rig().num_joints());
  b.pose = target * mask;
  at::Tensor weight = b.valid.unsqueeze(-1) * (1.0 - mask);
  torch::optim::Adam optimizer(model->parameters(), torch::optim::AdamOptions(3e-3));
  auto loss_of = [&] {
    InbetweenOutput out = run(*model, b);
    return ((out.stages[0] - target).abs() * weight).sum() / weight.sum() +
           ((out.stages[1] - target).abs() * weight).sum() / weight.sum();
  };
  const float initial = loss_of().item<float>();
  for (int step = 0; step < 60; ++step) {
    optimizer.zero_grad();
    at::Tensor loss = loss_of();
    loss.backward();
    optimizer.step();
  }
  EXPECT_LT(loss_of().item<float>(), 0.75f * initial);
}

}  // namespace
}  // namespace mf
