#include "prior/inbetween/citl.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/optim/adam.h>

#include "prior/motion/errors.h"
#include "tests/test_util.h"

namespace mf {
namespace {

constexpr int kWindow = 16;

std::map<std::string, double> tiny_hyperparameters() {
  return {{"width", 32}, {"layers", 1}, {"heads", 2}, {"ffn", 64}, {"time_dim", 8}, {"window", kWindow}, {"fps", 30}};
}

std::unique_ptr<InbetweenModel> tiny_citl(uint64_t seed = 0) {
  at::manual_seed(seed);
  auto model = make_citl(tiny_hyperparameters(), test::tiny_rig());
  const int64_t D = model->pose_size();
  model->stats().pose_mean = at::randn({D}) * 0.1;
  model->stats().pose_std = at::rand({D}) + 0.5;
  return model;
}

// Two windows: sample 0 uses all 16 frames with full keys at 0, 5 and 15;
// sample 1 has 10 valid frames, full keys at 0, 4 and 9 and a partial key at 3
// (two joints, no root position). Unknown entries of pose are zero.
InbetweenBatch two_windows(const InbetweenModel& model) {
  const int64_t J = model.rig().num_joints(), D = model.pose_size();
  InbetweenBatch b;
  b.known = at::zeros({2, kWindow, J + 1});
  b.valid = at::zeros({2, kWindow});
  for (int t : {0, 5, 15}) b.known[0][t].fill_(1.0);
  for (int t : {0, 4, 9}) b.known[1][t].fill_(1.0);
  b.known[1][3][1] = 1.0;
  b.known[1][3][4] = 1.0;
  b.valid[0].fill_(1.0);
  b.valid[1].narrow(0, 0, 10).fill_(1.0);
  b.pose = at::randn({2, kWindow, D}) * known_channel_mask(b.known, static_cast<int>(J));
  return b;
}

at::Tensor run(const InbetweenModel& model, const InbetweenBatch& batch) {
  InbetweenOutput out = model.forward(batch);
  EXPECT_EQ(out.stages.size(), 1u);
  return out.stages.back();
}

TEST(Citl, ShapesKindAndKnownValuesKept) {
  auto model = tiny_citl();
  EXPECT_EQ(model->kind(), kCitlKind);
  EXPECT_EQ(model->stage_names(), std::vector<std::string>{"citl"});
  EXPECT_EQ(model->window(), kWindow);
  EXPECT_EQ(model->fps(), 30.0);
  InbetweenBatch b = two_windows(*model);
  InbetweenOutput out = model->forward(b);
  ASSERT_EQ(out.stages.size(), 1u);
  EXPECT_EQ(out.stages[0].sizes(), (at::IntArrayRef{2, kWindow, model->pose_size()}));
  EXPECT_FALSE(out.contact_logits.defined());
  EXPECT_TRUE(at::isfinite(out.stages[0]).all().item<bool>());
  // Known values (valid frames) come back exactly, including the partial key.
  at::Tensor mask = known_channel_mask(b.known * b.valid.unsqueeze(-1), model->rig().num_joints());
  EXPECT_TRUE(at::equal(out.stages[0] * mask, b.pose * mask));
  // Shorter windows than `window` are accepted; longer ones are not.
  InbetweenBatch shorter{b.pose.narrow(1, 0, 6), b.known.narrow(1, 0, 6), b.valid.narrow(1, 0, 6)};
  EXPECT_EQ(run(*model, shorter).size(1), 6);
  InbetweenBatch longer{at::cat({b.pose, b.pose}, 1), at::cat({b.known, b.known}, 1), at::cat({b.valid, b.valid}, 1)};
  EXPECT_THROW(model->forward(longer), InputError);
  InbetweenBatch bad_known{b.pose, b.known.narrow(-1, 0, 3), b.valid};
  EXPECT_THROW(model->forward(bad_known), InputError);
}

TEST(Citl, UnknownValuesDoNotChangeTheOutput) {
  auto model = tiny_citl(1);
  InbetweenBatch b = two_windows(*model);
  at::Tensor reference = run(*model, b);
  at::Tensor mask = known_channel_mask(b.known, model->rig().num_joints());
  InbetweenBatch perturbed = b;
  perturbed.pose = b.pose + at::randn(b.pose.sizes()) * 10.0 * (1.0 - mask);
  EXPECT_TRUE(at::equal(run(*model, perturbed), reference));
}

TEST(Citl, PaddingFramesDoNotChangeValidFrames) {
  auto model = tiny_citl(2);
  InbetweenBatch b = two_windows(*model);
  at::Tensor reference = run(*model, b);
  // Garbage in the padding of sample 1: values, known flags, everything.
  InbetweenBatch garbage = b;
  garbage.pose = b.pose.clone();
  garbage.known = b.known.clone();
  garbage.pose[1].narrow(0, 10, kWindow - 10).normal_(0.0, 5.0);
  garbage.known[1].narrow(0, 10, kWindow - 10).fill_(1.0);
  at::Tensor out = run(*model, garbage);
  EXPECT_TRUE(at::allclose(out[0], reference[0], 1e-5, 1e-6));
  EXPECT_TRUE(at::allclose(out[1].narrow(0, 0, 10), reference[1].narrow(0, 0, 10), 1e-5, 1e-6));
  // The same window alone, unpadded, gives the same valid frames.
  InbetweenBatch alone{b.pose.narrow(0, 1, 1).narrow(1, 0, 10), b.known.narrow(0, 1, 1).narrow(1, 0, 10),
                       b.valid.narrow(0, 1, 1).narrow(1, 0, 10)};
  EXPECT_TRUE(at::allclose(run(*model, alone)[0], reference[1].narrow(0, 0, 10), 1e-4, 1e-5));
  // And the other sample of the batch does not matter either.
  InbetweenBatch first{b.pose.narrow(0, 0, 1), b.known.narrow(0, 0, 1), b.valid.narrow(0, 0, 1)};
  EXPECT_TRUE(at::allclose(run(*model, first)[0], reference[0], 1e-4, 1e-5));
}

TEST(Citl, ArbitraryKeySetsIncludingOneOrNone) {
  auto model = tiny_citl(3);
  const int64_t J = model->rig().num_joints(), D = model->pose_size();
  InbetweenBatch b;
  b.known = at::zeros({3, kWindow, J + 1});
  b.known[0][0].fill_(1.0);                             // one key
  b.known[1].narrow(0, 0, 12).fill_(1.0);               // dense context, then a gap
  b.known[2][7].narrow(0, 0, 1).fill_(1.0);             // only the root rotation of frame 7
  b.valid = at::ones({3, kWindow});
  b.pose = at::randn({3, kWindow, D}) * known_channel_mask(b.known, static_cast<int>(J));
  EXPECT_TRUE(at::isfinite(run(*model, b)).all().item<bool>());
  b.known.zero_();  // no key at all: still finite (no NaN from fully masked rows)
  EXPECT_TRUE(at::isfinite(run(*model, b)).all().item<bool>());
}

TEST(Citl, SequenceRecentringMakesTheOutputFollowTranslations) {
  auto model = tiny_citl(4);
  InbetweenBatch b = two_windows(*model);
  at::Tensor reference = run(*model, b);
  const int64_t D = model->pose_size();
  at::Tensor delta = at::zeros({D});
  delta.narrow(0, D - 3, 3).copy_(at::tensor({1.5f, -0.25f, 3.0f}));
  InbetweenBatch moved = b;
  at::Tensor root_known = b.known.narrow(-1, model->rig().num_joints(), 1);
  moved.pose = b.pose + delta * root_known;
  at::Tensor out = run(*model, moved);
  EXPECT_TRUE(at::allclose(out - delta, reference, 1e-4, 1e-4));
}

TEST(Citl, GradientsReachEveryParameter) {
  auto model = tiny_citl(5);
  model->train(true);
  InbetweenBatch b = two_windows(*model);
  run(*model, b).pow(2).sum().backward();
  for (const auto& [name, p] : model->named_parameters()) {
    ASSERT_TRUE(p.grad().defined()) << name;
    EXPECT_GT(p.grad().abs().sum().item<float>(), 0.0f) << name;
  }
}

TEST(Citl, HyperparametersRoundTrip) {
  auto defaults = make_citl({}, test::tiny_rig());
  std::map<std::string, double> expected = {{"width", 64}, {"layers", 2},  {"heads", 4}, {"ffn", 256},
                                            {"time_dim", 16}, {"window", 128}, {"fps", 30}};
  EXPECT_EQ(defaults->hyperparameters(), expected);
  auto model = tiny_citl();
  auto copy = make_citl(model->hyperparameters(), model->rig());
  EXPECT_EQ(copy->hyperparameters(), model->hyperparameters());
  EXPECT_EQ(copy->describe(), model->describe());
  EXPECT_NE(model->describe().find("citl"), std::string::npos);
  auto a = model->named_parameters(), c = copy->named_parameters();
  ASSERT_EQ(a.size(), c.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].first, c[i].first);
    EXPECT_EQ(a[i].second.sizes(), c[i].second.sizes()) << a[i].first;
  }
  // Stable, readable parameter names.
  EXPECT_EQ(a.front().first, "input.weight");
  auto factory = make_inbetweener(kCitlKind, model->hyperparameters(), model->rig());
  EXPECT_EQ(factory->kind(), kCitlKind);
  EXPECT_EQ(factory->num_parameters(), model->num_parameters());
}

TEST(Citl, SavedAndLoadedModelGivesTheSameOutput) {
  auto model = tiny_citl(7);
  model->train(false);
  InbetweenBatch b = two_windows(*model);
  const std::string path = test::scratch_dir("citl_model_file") + "/citl.mfm";
  save_inbetweener(*model, path);
  auto loaded = load_inbetweener(path);
  EXPECT_EQ(loaded->kind(), kCitlKind);
  EXPECT_EQ(loaded->hyperparameters(), model->hyperparameters());
  EXPECT_TRUE(at::equal(run(*loaded, b), run(*model, b)));
}

TEST(Citl, BadHyperparametersThrow) {
  RigInfo rig = test::tiny_rig();
  auto with = [](const std::string& key, double v) {
    auto h = tiny_hyperparameters();
    h[key] = v;
    return h;
  };
  EXPECT_THROW(make_citl(with("heads", 3), rig), InputError);  // does not divide 32
  EXPECT_THROW(make_citl(with("width", 0), rig), InputError);
  EXPECT_THROW(make_citl(with("layers", 1.5), rig), InputError);
  EXPECT_THROW(make_citl(with("layers", 0), rig), InputError);
  EXPECT_THROW(make_citl(with("ffn", -4), rig), InputError);
  EXPECT_THROW(make_citl(with("time_dim", 7), rig), InputError);
  EXPECT_THROW(make_citl(with("time_dim", 32), rig), InputError);  // not below width
  EXPECT_THROW(make_citl(with("window", 1), rig), InputError);
  EXPECT_THROW(make_citl(with("fps", -30), rig), InputError);
  EXPECT_THROW(make_citl(with("fps", std::nan("")), rig), InputError);
  EXPECT_THROW(make_citl(with("dropout", 0.1), rig), InputError);  // unknown key
  EXPECT_NO_THROW(make_citl(with("heads", 4), rig));
}

TEST(Citl, OverfitsOneBatch) {
  auto model = tiny_citl(6);
  model->train(true);
  InbetweenBatch b = two_windows(*model);
  at::Tensor target = at::randn(b.pose.sizes()) * 0.5;
  at::Tensor mask = known_channel_mask(b.known, model->rig().num_joints());
  b.pose = target * mask;
  at::Tensor weight = b.valid.unsqueeze(-1) * (1.0 - mask);
  torch::optim::Adam optimizer(model->parameters(), torch::optim::AdamOptions(3e-3));
  auto loss_of = [&] { return ((run(*model, b) - target).abs() * weight).sum() / weight.sum(); };
  const float initial = loss_of().item<float>();
  for (int step = 0; step < 40; ++step) {
    optimizer.zero_grad();
    at::Tensor loss = loss_of();
    loss.backward();
    optimizer.step();
  }
  EXPECT_LT(loss_of().item<float>(), 0.6f * initial);
}

}  // namespace
}  // namespace mf
