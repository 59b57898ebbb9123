// The transformer in-betweeners (prior/inbetween/two_stage.h, citl.h): what
// every kind guarantees, as one suite over the kinds, then what only one kind
// does.
#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <torch/optim/adam.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "prior/inbetween/citl.h"
#include "prior/inbetween/keyframe_net.h"
#include "prior/inbetween/two_stage.h"
#include "prior/model/model_file.h"
#include "prior/motion/errors.h"
#include "tests/test_util.h"

namespace mf {
namespace {

constexpr int kWindow = 16;

using Factory = std::function<std::unique_ptr<InbetweenModel>(const std::map<std::string, double>&, const RigInfo&)>;

struct Kind {
  std::string name;
  Factory make;
  std::map<std::string, double> tiny;      // the hyperparameters of the tests' models
  std::map<std::string, double> defaults;  // what an empty map gives
  std::vector<std::string> stages;
  bool contacts;
  std::string described;                       // found in describe() of the tiny model
  std::vector<std::string> parameter_names;    // the first one first, then some others
  std::vector<std::pair<std::string, double>> bad_for_kind;  // rejected besides the shared ones
  int overfit_steps;
  float overfit_ratio;  // the loss after overfit_steps, relative to the first
};

Kind two_stage_kind() {
  return {kTwoStageKind,
          make_two_stage,
          {{"width", 32}, {"layers", 1}, {"heads", 2}, {"ffn", 48}, {"window", kWindow}, {"fps", 30}},
          {{"width", 64}, {"layers", 2}, {"heads", 4}, {"ffn", 128}, {"window", 128}, {"fps", 30}},
          {"context", "detail"},
          true,
          "context 1x32",
          {"context.input.fc1.weight", "context.layers.0.attn.q.weight"},
          {},
          60,
          0.75f};
}

Kind citl_kind() {
  return {kCitlKind,
          make_citl,
          {{"width", 32}, {"layers", 1}, {"heads", 2}, {"ffn", 64}, {"time_dim", 8}, {"window", kWindow}, {"fps", 30}},
          {{"width", 64}, {"layers", 2}, {"heads", 4}, {"ffn", 256}, {"time_dim", 16}, {"window", 128}, {"fps", 30}},
          {"citl"},
          false,
          "citl",
          {"input.weight"},
          {{"time_dim", 7}, {"time_dim", 32}},  // odd; not below width
          40,
          0.6f};
}

Kind keyframe_kind() {
  return {kKeyframeKind,
          make_keyframe_net,
          {{"width", 32}, {"layers", 1}, {"heads", 2}, {"ffn", 48}, {"window", kWindow}, {"fps", 30},
           {"min_spacing", 2}, {"max_spacing", 5}},
          {{"width", 64}, {"layers", 2}, {"heads", 4}, {"ffn", 128}, {"window", 256}, {"fps", 30},
           {"min_spacing", 5}, {"max_spacing", 30}},
          {"keyframe", "refine"},
          true,
          "KeyframeNet 1x32",
          {"keyframe.input.fc1.weight", "keyframe.keyframe.fc1.weight", "refine.layers.0.attn.relative.fc1.weight"},
          {{"min_spacing", 0}, {"max_spacing", 3}},  // max_spacing below twice min_spacing
          60,
          0.75f};
}

std::unique_ptr<InbetweenModel> tiny(const Kind& kind, uint64_t seed) {
  at::manual_seed(seed);
  auto model = kind.make(kind.tiny, test::tiny_rig());
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

// Every output tensor: the stages, then the contact logits if the kind has them.
std::vector<at::Tensor> outputs(const InbetweenModel& model, const InbetweenBatch& batch) {
  InbetweenOutput out = model.forward(batch);
  std::vector<at::Tensor> all = out.stages;
  if (out.contact_logits.defined()) all.push_back(out.contact_logits);
  // Keyframe kinds: KeyframeNet's own outputs too (its stage is detached from them).
  for (const at::Tensor& t : {out.keyframe_poses, out.keyframe_logits, out.keyframes})
    if (t.defined()) all.push_back(t);
  return all;
}

at::Tensor final_stage(const InbetweenModel& model, const InbetweenBatch& batch) {
  return model.forward(batch).stages.back();
}

// CTest names the cases .../<kind> (gtest_discover_tests prints the parameter).
void PrintTo(const Kind& kind, std::ostream* os) { *os << kind.name; }

class TransformerKind : public ::testing::TestWithParam<Kind> {};

TEST_P(TransformerKind, ShapesAndKind) {
  const Kind& kind = GetParam();
  auto model = tiny(kind, 0);
  EXPECT_EQ(model->kind(), kind.name);
  EXPECT_EQ(model->stage_names(), kind.stages);
  EXPECT_EQ(model->window(), kWindow);
  EXPECT_EQ(model->fps(), 30.0);
  ASSERT_GT(model->rig().num_feet(), 0);
  InbetweenBatch b = two_windows(*model);
  InbetweenOutput out = model->forward(b);
  ASSERT_EQ(out.stages.size(), kind.stages.size());
  for (const at::Tensor& s : out.stages) {
    EXPECT_EQ(s.sizes(), (at::IntArrayRef{2, kWindow, model->pose_size()}));
    EXPECT_TRUE(at::isfinite(s).all().item<bool>());
  }
  ASSERT_EQ(out.contact_logits.defined(), kind.contacts);
  if (kind.contacts) EXPECT_EQ(out.contact_logits.sizes(), (at::IntArrayRef{2, kWindow, model->rig().num_feet()}));
  // Shorter windows than `window` are accepted; longer ones and bad shapes are not.
  InbetweenBatch shorter{b.pose.narrow(1, 0, 6), b.known.narrow(1, 0, 6), b.valid.narrow(1, 0, 6)};
  EXPECT_EQ(final_stage(*model, shorter).size(1), 6);
  InbetweenBatch one{b.pose.narrow(1, 0, 1), b.known.narrow(1, 0, 1), b.valid.narrow(1, 0, 1)};
  EXPECT_TRUE(at::isfinite(final_stage(*model, one)).all().item<bool>());
  InbetweenBatch longer{at::cat({b.pose, b.pose}, 1), at::cat({b.known, b.known}, 1), at::cat({b.valid, b.valid}, 1)};
  EXPECT_THROW(model->forward(longer), InputError);
  EXPECT_THROW(model->forward(InbetweenBatch{b.pose, b.known.narrow(-1, 0, 3), b.valid}), InputError);
  EXPECT_THROW(model->forward(InbetweenBatch{b.pose.narrow(-1, 0, 7), b.known, b.valid}), InputError);
  EXPECT_THROW(model->forward(InbetweenBatch{b.pose, b.known, at::Tensor()}), InputError);
}

TEST_P(TransformerKind, UnknownValuesDoNotChangeTheOutput) {
  auto model = tiny(GetParam(), 1);
  InbetweenBatch b = two_windows(*model);
  const std::vector<at::Tensor> reference = outputs(*model, b);
  at::Tensor mask = known_channel_mask(b.known, model->rig().num_joints());
  InbetweenBatch perturbed = b;
  perturbed.pose = b.pose + at::randn(b.pose.sizes()) * 10.0 * (1.0 - mask);
  const std::vector<at::Tensor> out = outputs(*model, perturbed);
  ASSERT_EQ(out.size(), reference.size());
  for (size_t i = 0; i < out.size(); ++i) EXPECT_TRUE(at::equal(out[i], reference[i])) << "output " << i;
}

TEST_P(TransformerKind, KnownValuesDoChangeTheOutput) {
  auto model = tiny(GetParam(), 2);
  InbetweenBatch b = two_windows(*model);
  at::Tensor reference = final_stage(*model, b);
  InbetweenBatch changed = b;
  changed.pose = b.pose.clone();
  changed.pose[0][5].mul_(-1.0);  // a full key in the middle of sample 0
  at::Tensor out = final_stage(*model, changed);
  EXPECT_FALSE(at::allclose(out[0], reference[0]));
  EXPECT_TRUE(at::allclose(out[1], reference[1], 1e-5, 1e-6));  // samples are independent
}

TEST_P(TransformerKind, PaddingFramesDoNotChangeValidFrames) {
  auto model = tiny(GetParam(), 3);
  InbetweenBatch b = two_windows(*model);
  const std::vector<at::Tensor> reference = outputs(*model, b);
  // Garbage in the padding of sample 1: values, known flags, everything.
  InbetweenBatch garbage = b;
  garbage.pose = b.pose.clone();
  garbage.known = b.known.clone();
  garbage.pose[1].narrow(0, 10, kWindow - 10).normal_(0.0, 5.0);
  garbage.known[1].narrow(0, 10, kWindow - 10).fill_(1.0);
  const std::vector<at::Tensor> out = outputs(*model, garbage);
  // The same window alone, unpadded, and the other sample alone.
  InbetweenBatch alone{b.pose.narrow(0, 1, 1).narrow(1, 0, 10), b.known.narrow(0, 1, 1).narrow(1, 0, 10),
                       b.valid.narrow(0, 1, 1).narrow(1, 0, 10)};
  InbetweenBatch first{b.pose.narrow(0, 0, 1), b.known.narrow(0, 0, 1), b.valid.narrow(0, 0, 1)};
  const std::vector<at::Tensor> single = outputs(*model, alone), other = outputs(*model, first);
  ASSERT_EQ(out.size(), reference.size());
  for (size_t i = 0; i < out.size(); ++i) {
    const at::Tensor valid = reference[i][1].narrow(0, 0, 10);
    EXPECT_TRUE(at::allclose(out[i][0], reference[i][0], 1e-5, 1e-6)) << "output " << i;
    EXPECT_TRUE(at::allclose(out[i][1].narrow(0, 0, 10), valid, 1e-5, 1e-6)) << "output " << i;
    EXPECT_TRUE(at::allclose(single[i][0], valid, 1e-4, 1e-5)) << "output " << i;
    EXPECT_TRUE(at::allclose(other[i][0], reference[i][0], 1e-4, 1e-5)) << "output " << i;
  }
}

TEST_P(TransformerKind, ArbitraryKeySetsIncludingOneOrNone) {
  auto model = tiny(GetParam(), 4);
  const int64_t J = model->rig().num_joints(), D = model->pose_size();
  InbetweenBatch b;
  b.known = at::zeros({3, kWindow, J + 1});
  b.known[0][0].fill_(1.0);                  // one key
  b.known[1].narrow(0, 0, 12).fill_(1.0);    // dense context, then a gap to the end
  b.known[2][7].narrow(0, 0, 1).fill_(1.0);  // only the root rotation of frame 7
  b.valid = at::ones({3, kWindow});
  b.pose = at::randn({3, kWindow, D}) * known_channel_mask(b.known, static_cast<int>(J));
  EXPECT_TRUE(at::isfinite(final_stage(*model, b)).all().item<bool>());
  // No key at all: still finite (no NaN from fully masked rows), whatever the values.
  b.known.zero_();
  EXPECT_TRUE(at::isfinite(final_stage(*model, b)).all().item<bool>());
  b.pose.zero_();
  EXPECT_TRUE(at::isfinite(final_stage(*model, b)).all().item<bool>());
}

TEST_P(TransformerKind, GradientsReachEveryParameter) {
  auto model = tiny(GetParam(), 5);
  model->train(true);
  InbetweenBatch b = two_windows(*model);
  at::Tensor loss = at::zeros({});
  for (const at::Tensor& out : outputs(*model, b)) loss = loss + out.pow(2).sum();
  loss.backward();
  for (const auto& [name, p] : model->named_parameters()) {
    ASSERT_TRUE(p.grad().defined()) << name;
    EXPECT_GT(p.grad().abs().sum().item<float>(), 0.0f) << name;
  }
}

TEST_P(TransformerKind, HyperparametersRoundTrip) {
  const Kind& kind = GetParam();
  EXPECT_EQ(kind.make({}, test::tiny_rig())->hyperparameters(), kind.defaults);
  auto model = tiny(kind, 0);
  auto copy = kind.make(model->hyperparameters(), model->rig());
  EXPECT_EQ(copy->hyperparameters(), model->hyperparameters());
  EXPECT_EQ(copy->describe(), model->describe());
  EXPECT_NE(model->describe().find(kind.described), std::string::npos) << model->describe();
  auto a = model->named_parameters(), c = copy->named_parameters();
  ASSERT_EQ(a.size(), c.size());
  std::vector<std::string> names;
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].first, c[i].first);
    EXPECT_EQ(a[i].second.sizes(), c[i].second.sizes()) << a[i].first;
    names.push_back(a[i].first);
  }
  // Stable, readable parameter names.
  EXPECT_EQ(names.front(), kind.parameter_names.front());
  for (const std::string& n : kind.parameter_names)
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
  auto factory = make_inbetweener(kind.name, model->hyperparameters(), model->rig());
  EXPECT_EQ(factory->kind(), kind.name);
  EXPECT_EQ(factory->num_parameters(), model->num_parameters());
}

TEST_P(TransformerKind, ModelFileRoundTripGivesTheSameOutputs) {
  const Kind& kind = GetParam();
  auto model = tiny(kind, 7);
  model->train(false);
  model->stats().pose_std[3] = 0.0;  // a constant channel stays finite
  InbetweenBatch b = two_windows(*model);
  const std::vector<at::Tensor> reference = outputs(*model, b);
  EXPECT_TRUE(at::isfinite(reference.front()).all().item<bool>());
  std::vector<uint8_t> bytes = serialize_inbetweener(*model);
  const std::string path = test::scratch_dir("transformer_model_file_" + kind.name) + "/model.mfm";
  save_inbetweener(*model, path);
  std::vector<std::unique_ptr<InbetweenModel>> loaded_models;
  loaded_models.push_back(deserialize_inbetweener(bytes.data(), bytes.size(), "memory"));
  loaded_models.push_back(load_inbetweener(path));
  for (const auto& loaded : loaded_models) {
    EXPECT_EQ(loaded->kind(), kind.name);
    EXPECT_EQ(loaded->hyperparameters(), model->hyperparameters());
    const std::vector<at::Tensor> out = outputs(*loaded, b);
    ASSERT_EQ(out.size(), reference.size());
    for (size_t i = 0; i < out.size(); ++i) EXPECT_TRUE(at::equal(out[i], reference[i])) << "output " << i;
  }
}

TEST_P(TransformerKind, BadHyperparametersThrow) {
  const Kind& kind = GetParam();
  const RigInfo rig = test::tiny_rig();
  auto with = [&](const std::string& key, double v) {
    auto h = kind.tiny;
    h[key] = v;
    return h;
  };
  std::vector<std::pair<std::string, double>> bad = {
      {"heads", 3},  // does not divide 32
      {"heads", 0},  {"width", 0},    {"layers", 1.5},          {"layers", 0},
      {"ffn", -4},   {"window", 1},   {"fps", -30},             {"fps", std::nan("")},
      {"dropout", 0.1},  // unknown key
  };
  bad.insert(bad.end(), kind.bad_for_kind.begin(), kind.bad_for_kind.end());
  for (const auto& [key, value] : bad) EXPECT_THROW(kind.make(with(key, value), rig), InputError) << key << " " << value;
  EXPECT_NO_THROW(kind.make(with("heads", 4), rig));
}

TEST_P(TransformerKind, ParameterCountMatchesTheBuiltNetwork) {
  const Kind& kind = GetParam();
  const InbetweenNetwork* product_kind = find_inbetween_network(kind.name);
  ASSERT_TRUE(product_kind && product_kind->count_parameters);
  const RigInfo rig = test::tiny_rig();
  std::vector<std::map<std::string, double>> sizes = {kind.tiny, {}};
  for (const auto& [key, value] : std::vector<std::pair<std::string, double>>{
           {"layers", 3}, {"ffn", 20}, {"heads", 8}, {"width", 48}}) {
    auto h = kind.tiny;
    h[key] = value;
    sizes.push_back(h);
  }
  for (const auto& h : sizes) {
    EXPECT_EQ(product_kind->count_parameters(h, rig), kind.make(h, rig)->num_parameters())
        << ::testing::PrintToString(h);
  }
  EXPECT_THROW(product_kind->count_parameters({{"heads", 3}}, rig), InputError);
}

// A file whose hyperparameters are within their bounds but describe a network
// of billions of parameters is refused from the count, before that network
// is built (building it took 22 s and gigabytes).
TEST_P(TransformerKind, AHugeNetworkIsRefusedBeforeItIsBuilt) {
  const Kind& kind = GetParam();
  auto model = tiny(kind, 3);
  std::vector<std::pair<std::string, at::Tensor>> tensors = {{"stats.pose_mean", model->stats().pose_mean},
                                                             {"stats.pose_std", model->stats().pose_std}};
  for (auto& named : model->named_parameters()) tensors.push_back(named);
  auto h = model->hyperparameters();
  h["width"] = 2048;
  h["layers"] = 32;
  h["ffn"] = 16384;
  const std::vector<uint8_t> bytes = serialize_model_file(kind.name, h, model->rig(), tensors);
  try {
    deserialize_inbetweener(bytes.data(), bytes.size(), "huge.mfm");
    FAIL() << "a file describing a huge network was loaded";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("huge.mfm: invalid hyperparameters"), std::string::npos) << message;
    EXPECT_NE(message.find("parameters, but the file holds " + std::to_string(model->num_parameters() + 2 * model->pose_size()) + " values"),
              std::string::npos)
        << message;
  }
}

TEST_P(TransformerKind, OverfitsOneBatch) {
  const Kind& kind = GetParam();
  auto model = tiny(kind, 6);
  model->train(true);
  InbetweenBatch b = two_windows(*model);
  at::Tensor target = at::randn(b.pose.sizes()) * 0.5;
  at::Tensor mask = known_channel_mask(b.known, model->rig().num_joints());
  b.pose = target * mask;
  at::Tensor weight = b.valid.unsqueeze(-1) * (1.0 - mask);
  torch::optim::Adam optimizer(model->parameters(), torch::optim::AdamOptions(3e-3));
  auto loss_of = [&] {
    at::Tensor loss = at::zeros({});
    InbetweenOutput out = model->forward(b);
    std::vector<at::Tensor> poses = out.stages;
    if (out.keyframe_poses.defined()) poses.push_back(out.keyframe_poses);
    for (const at::Tensor& stage : poses) loss = loss + ((stage - target).abs() * weight).sum() / weight.sum();
    return loss;
  };
  const float initial = loss_of().item<float>();
  for (int step = 0; step < kind.overfit_steps; ++step) {
    optimizer.zero_grad();
    at::Tensor loss = loss_of();
    loss.backward();
    optimizer.step();
  }
  EXPECT_LT(loss_of().item<float>(), kind.overfit_ratio * initial);
}

INSTANTIATE_TEST_SUITE_P(Kinds, TransformerKind, ::testing::Values(two_stage_kind(), citl_kind(), keyframe_kind()));

// CITL alone keeps the known values of valid frames exactly, partial keys included.
// Per window, joint and channel: the linear interpolation of `pose` between
// the nearest valid frames where that joint (or, for the root position, the
// root) is known, held before the first and after the last.
at::Tensor interpolated_per_joint(const InbetweenBatch& b, int64_t J) {
  at::Tensor out = b.pose.clone();
  for (int64_t w = 0; w < b.pose.size(0); ++w) {
    const int64_t T = b.valid[w].sum().item<int64_t>();
    for (int64_t j = 0; j <= J; ++j) {
      const int64_t c0 = 6 * j, width = j < J ? 6 : 3;
      std::vector<int64_t> keys;
      for (int64_t t = 0; t < T; ++t)
        if (b.known[w][t][j].item<float>() > 0.5f) keys.push_back(t);
      for (int64_t t = 0; t < T && !keys.empty(); ++t) {
        auto next = std::lower_bound(keys.begin(), keys.end(), t);
        const int64_t after = next == keys.end() ? keys.back() : *next;
        const int64_t before = next == keys.end() ? keys.back() : (*next == t ? t : (next == keys.begin() ? after : *(next - 1)));
        const double a = after == before ? 0.0 : static_cast<double>(t - before) / static_cast<double>(after - before);
        out[w][t].narrow(0, c0, width).copy_(b.pose[w][before].narrow(0, c0, width) * (1 - a) +
                                             b.pose[w][after].narrow(0, c0, width) * a);
      }
    }
  }
  return out;
}

// "interp_input" 1: the Context Transformer corrects each joint's own
// interpolation between the frames it is known at, through a gate that starts
// closed, so a new model's context stage is that interpolation.
TEST(TwoStage, InterpolatedInputStartsAtEachJointsInterpolation) {
  std::map<std::string, double> hp = two_stage_kind().tiny;
  hp["interp_input"] = 1;
  at::manual_seed(3);
  auto model = make_two_stage(hp, test::tiny_rig());
  const int64_t J = model->rig().num_joints(), D = model->pose_size();
  model->stats().pose_mean = at::randn({D}) * 0.1;
  model->stats().pose_std = at::rand({D}) + 0.5;
  InbetweenBatch b = two_windows(*model);
  at::Tensor expected = interpolated_per_joint(b, J);
  at::Tensor context = model->forward(b).stages[0];
  for (int64_t w = 0; w < 2; ++w) {
    const int64_t T = b.valid[w].sum().item<int64_t>();
    EXPECT_TRUE(at::allclose(context[w].narrow(0, 0, T), expected[w].narrow(0, 0, T), 1e-4, 1e-5)) << "window " << w;
  }
  // The partial key at frame 3 of window 1 bends its two joints' lines only.
  EXPECT_GT((expected[1][2].narrow(0, 6, 12) - (b.pose[1][0].narrow(0, 6, 12) * 7 + b.pose[1][9].narrow(0, 6, 12) * 2) / 9)
                .abs().max().item<float>(), 1e-3f);

  // Opened, the gate lets the correction through.
  {
    torch::NoGradGuard no_grad;
    for (auto& [name, t] : model->named_parameters())
      if (name == "context.gate") t.fill_(0.5);
  }
  EXPECT_FALSE(at::allclose(model->forward(b).stages[0][0], expected[0], 1e-3, 1e-3));

  EXPECT_EQ(model->hyperparameters().at("interp_input"), 1.0);
  EXPECT_NE(model->describe().find("on interpolated input"), std::string::npos);
  EXPECT_EQ(two_stage_parameter_count(hp, model->rig()), model->num_parameters());
  // Models of the original design do not name the key (their files stay as they were).
  EXPECT_EQ(tiny(two_stage_kind(), 0)->hyperparameters().count("interp_input"), 0u);
}

TEST(Citl, KnownValuesComeBackExactly) {
  auto model = tiny(citl_kind(), 0);
  InbetweenBatch b = two_windows(*model);
  at::Tensor mask = known_channel_mask(b.known * b.valid.unsqueeze(-1), model->rig().num_joints());
  EXPECT_TRUE(at::equal(final_stage(*model, b) * mask, b.pose * mask));
}

// CITL re-centres each sequence on its keys: moving every known root position
// moves the output by as much.
TEST(Citl, SequenceRecentringMakesTheOutputFollowTranslations) {
  auto model = tiny(citl_kind(), 4);
  InbetweenBatch b = two_windows(*model);
  at::Tensor reference = final_stage(*model, b);
  const int64_t D = model->pose_size();
  at::Tensor delta = at::zeros({D});
  delta.narrow(0, D - 3, 3).copy_(at::tensor({1.5f, -0.25f, 3.0f}));
  InbetweenBatch moved = b;
  at::Tensor root_known = b.known.narrow(-1, model->rig().num_joints(), 1);
  moved.pose = b.pose + delta * root_known;
  EXPECT_TRUE(at::allclose(final_stage(*model, moved) - delta, reference, 1e-4, 1e-4));
}

}  // namespace
}  // namespace mf
