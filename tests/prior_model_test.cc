// The prior's model: shapes, short windows, continuous time, gradients to the
// latents through a frozen network, the model file and its error messages, and
// a few steps of the training program.
#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "prior/model/model_file.h"
#include "prior/model/nemf.h"
#include "prior/model/representation.h"
#include "prior/motion/errors.h"
#include "prior/motion/kinematics_torch.h"
#include "prior/motion/motion_bvh.h"
#include "prior/motion/rotations_torch.h"
#include "tests/gradient_check.h"
#include "tests/test_util.h"
#include "training/prior_trainer.h"

namespace mf {
namespace {

using test::tiny_nemf_config;
using test::tiny_rig;

TEST(PriorModel, RigFindsFeetAndForward) {
  RigInfo rig = tiny_rig();
  ASSERT_EQ(rig.num_feet(), 2);  // Foot_L, Foot_R (no toes in the small skeleton)
  EXPECT_EQ(rig.skeleton.names[rig.foot_joints[0]], "Foot_L");
  EXPECT_EQ(rig.foot_thresholds[0], 0.08);
  EXPECT_NEAR(rig.root_forward.norm(), 1.0, 1e-12);
}

TEST(PriorModel, CanonicalWindowRoundTrip) {
  RigInfo rig = tiny_rig();
  Motion m = test::random_motion(rig.skeleton, 40, 30.0, 5);
  WindowTensors w = window_tensors(m, 10, 20, rig, 0);
  // Frame 0 of the window: root on the ground origin, heading along +Z.
  EXPECT_NEAR(w.root_positions[0][0][0].item<float>(), 0.0f, 1e-5);
  EXPECT_NEAR(w.root_positions[0][0][2].item<float>(), 0.0f, 1e-5);
  at::Tensor h = heading_rotation(w.local_rotations.select(-3, 0), rig.root_forward);
  EXPECT_NEAR(h[0][0][0][0].item<float>(), 1.0f, 1e-5);
  Motion back = m;
  for (auto& q : back.rotations) q = Eigen::Quaterniond(0.5, 0.5, 0.5, 0.5);
  write_window(w.local_rotations, w.root_positions, canonical_transform(m, 10, rig), &back, 10);
  for (int f = 10; f < 30; ++f) {
    EXPECT_LT((back.root_positions[f] - m.root_positions[f]).norm(), 1e-5);
    for (int j = 0; j < m.num_joints(); ++j) {
      EXPECT_LT(back.rotation(f, j).angularDistance(m.rotation(f, j)), 1e-5);
    }
  }
}

TEST(PriorModel, GmpTargetsIntegrateBackToTheRootPath) {
  RigInfo rig = tiny_rig();
  Motion m = test::random_motion(rig.skeleton, 30, 30.0, 9);
  WindowTensors w = window_tensors(m, 0, 30, rig, 0);
  GmpTargets t = gmp_targets(w.local_rotations, w.root_positions, rig, 30.0);
  at::Tensor h = heading_rotation(w.local_rotations.select(-3, 0), rig.root_forward);
  at::Tensor start = ground_xz(w.root_positions.select(1, 0));
  at::Tensor p = integrate_root(t.velocity, t.height, h, 30.0, start);
  EXPECT_LT((p - w.root_positions).abs().max().item<float>(), 1e-4);
}

// The GMP's input from positions the caller already has (the solver's one FK
// pass) equals the one computed from the rotations alone.
TEST(PriorModel, GmpInputsFromPositionsAtTheOriginMatch) {
  RigInfo rig = tiny_rig();
  Motion m = test::random_motion(rig.skeleton, 30, 30.0, 11);
  WindowTensors w = window_tensors(m, 0, 30, rig, 0);
  // A heading that is not the canonical one at every frame.
  at::Tensor rot = w.local_rotations.clone();
  at::Tensor turn = torch_rot::quat_to_matrix(at::tensor({0.8f, 0.0f, 0.6f, 0.0f}));
  rot.select(-3, 0).copy_(at::matmul(turn, rot.select(-3, 0)));
  at::Tensor offsets = offsets_tensor(rig.skeleton);
  at::Tensor pos = forward_kinematics(rig.skeleton.parents, offsets, rot, at::zeros({1, 30, 3})).positions;
  at::Tensor a = gmp_inputs(rot, rig), b = gmp_inputs(rot, pos, rig);
  ASSERT_EQ(a.sizes(), b.sizes());
  EXPECT_LT((a - b).abs().max().item<float>(), 1e-5);
  EXPECT_GT(a.abs().max().item<float>(), 0.1f);
}

// The heading node: R_y(yaw) of the root's forward axis on the ground, in value
// and (finite differences on every entry, any matrices) in gradient.
TEST(PriorModel, HeadingRotationValueAndGradient) {
  at::manual_seed(3);
  const Eigen::Vector3d forward = Eigen::Vector3d(0.3, -0.2, 0.9).normalized();
  at::Tensor root = at::randn({2, 3, 3, 3}, at::kDouble).requires_grad_(true);
  at::Tensor h = heading_rotation(root, forward);
  ASSERT_EQ(h.sizes(), (at::IntArrayRef{2, 3, 3, 3}));
  at::Tensor fwd = at::tensor({forward.x(), forward.y(), forward.z()}, at::kDouble);
  at::Tensor f = at::matmul(root.detach(), fwd);  // [2, 3, 3]
  at::Tensor n = (f.select(-1, 0).square() + f.select(-1, 2).square() + 1e-12).sqrt();
  EXPECT_LT((h.select(-1, 2).select(-1, 0) - f.select(-1, 0) / n).abs().max().item<double>(), 1e-12);  // sin
  EXPECT_LT((h.select(-1, 0).select(-1, 0) - f.select(-1, 2) / n).abs().max().item<double>(), 1e-12);  // cos
  EXPECT_TRUE(at::equal(h.select(-2, 1).detach(), at::tensor({0.0, 1.0, 0.0}, at::kDouble).expand({2, 3, 3})));
  const at::Tensor w = at::randn({2, 3, 3, 3}, at::kDouble);
  auto loss = [&](const at::Tensor& r) { return (heading_rotation(r, forward) * w).sum(); };
  loss(root).backward();
  test::expect_gradient_matches_finite_differences(loss, root, "root rotations");
  // Strided float input (a joint of a window), float out; a vertical forward gives a finite identity-like heading.
  at::Tensor win = at::randn({1, 4, 5, 3, 3});
  EXPECT_EQ(heading_rotation(win.select(-3, 0), forward).scalar_type(), at::kFloat);
  at::Tensor up = heading_rotation(at::eye(3).unsqueeze(0), Eigen::Vector3d::UnitY());
  EXPECT_TRUE(at::isfinite(up).all().item<bool>());
  EXPECT_THROW(heading_rotation(at::eye(3, at::kLong), forward), InputError);
}

// One window's decode (the latent projections as matrix-vector products) equals
// the same latents decoded in a batch (matrix products), values and gradients.
TEST(PriorModel, SingleWindowDecodeMatchesBatchedDecode) {
  at::manual_seed(4);
  RigInfo rig = tiny_rig();
  NemfModel model(tiny_nemf_config(), rig);
  const NemfConfig& c = model.config();
  at::Tensor z_l = at::randn({3, c.zl}).requires_grad_(true), z_g = at::randn({3, c.zg}).requires_grad_(true);
  at::Tensor frames = at::arange(0.0, 20.0, 0.5);
  at::Tensor batched = model.decode(frames, z_l, z_g);
  const at::Tensor w = at::randn(batched.select(0, 1).sizes());  // a rotation's squared entries sum to 3
  (batched.select(0, 1) * w).sum().backward();
  for (int b = 0; b < 3; ++b) {
    at::Tensor zl1 = z_l.detach().narrow(0, b, 1).clone().requires_grad_(true);
    at::Tensor zg1 = z_g.detach().narrow(0, b, 1).clone().requires_grad_(true);
    at::Tensor one = model.decode(frames, zl1, zg1);
    EXPECT_LT((one.select(0, 0) - batched.select(0, b).detach()).abs().max().item<float>(), 1e-5) << b;
    if (b != 1) continue;
    (one.select(0, 0) * w).sum().backward();
    EXPECT_LT((zl1.grad() - z_l.grad().narrow(0, 1, 1)).abs().max().item<float>(), 1e-4);
    EXPECT_LT((zg1.grad() - z_g.grad().narrow(0, 1, 1)).abs().max().item<float>(), 1e-4);
    EXPECT_GT(zl1.grad().abs().max().item<float>(), 1e-3f);
  }
}

TEST(PriorModel, EncodeDecodeShapesShortWindowsAndContinuousTime) {
  at::manual_seed(0);
  RigInfo rig = tiny_rig();
  NemfModel model(tiny_nemf_config(), rig);
  Motion m = test::random_motion(rig.skeleton, 20, 30.0, 1);
  WindowTensors w = window_tensors(m, 0, 20, rig, 0);  // shorter than the 32-frame window
  NemfLatent z = model.encode(w.local_rotations, at::ones({1, 20}));
  EXPECT_EQ(z.mu_l.sizes(), (at::IntArrayRef{1, 8}));
  EXPECT_EQ(z.mu_g.sizes(), (at::IntArrayRef{1, 4}));
  at::Tensor frames = at::arange(0.0, 19.0, 0.25);  // 120 fps decode
  at::Tensor rot = model.decode(frames, z.mu_l, z.mu_g);
  ASSERT_EQ(rot.sizes(), (at::IntArrayRef{1, frames.size(0), rig.num_joints(), 3, 3}));
  // Orthonormal rotations.
  at::Tensor eye = at::matmul(rot, rot.transpose(-1, -2));
  EXPECT_LT((eye - at::eye(3)).abs().max().item<float>(), 1e-4);
  EXPECT_THROW(model.encode(w.local_rotations.narrow(1, 0, 1), at::ones({1, 1})), InputError);
}

TEST(PriorModel, GradientsReachTheLatentThroughAFrozenNetwork) {
  at::manual_seed(0);
  RigInfo rig = tiny_rig();
  NemfModel model(tiny_nemf_config(), rig);
  model.set_requires_grad(false);
  at::Tensor zl = at::zeros({1, 8}).set_requires_grad(true);
  at::Tensor zg = at::zeros({1, 4}).set_requires_grad(true);
  at::Tensor rot = model.decode(at::arange(0, 32, at::kFloat), zl, zg);
  GmpOutput g = model.predict_global(rot);
  at::Tensor loss = rot.sum() + model.root_positions(rot, g).sum();
  loss.backward();
  ASSERT_TRUE(zl.grad().defined());
  EXPECT_GT(zl.grad().abs().sum().item<float>(), 0.0f);
  EXPECT_GT(zg.grad().abs().sum().item<float>(), 0.0f);
  for (auto& p : model.parameters()) EXPECT_FALSE(p.grad().defined());
}

TEST(PriorModel, FrozenDecoderNodeMatchesTheModulePath) {
  // A frozen model decodes one window through one hand-written autograd node;
  // values and latent gradients must be the module path's (the unfrozen model).
  at::manual_seed(5);
  RigInfo rig = tiny_rig();
  NemfModel model(tiny_nemf_config(), rig);
  {
    at::NoGradGuard no_grad;  // layer norms and head away from their initial values
    for (auto& [name, p] : model.named_parameters()) {
      if (name.rfind("decoder.", 0) == 0) p.add_(0.3 * at::randn_like(p));
    }
  }
  const NemfConfig& c = model.config();
  const at::Tensor z_l0 = at::randn({1, c.zl}), z_g0 = at::randn({1, c.zg});
  const at::Tensor frames = at::arange(0.0, 31.0, 0.25);  // 124 rows: the node's two halves
  at::Tensor w;
  auto decode = [&](at::Tensor* g_zl, at::Tensor* g_zg) {
    at::Tensor zl = z_l0.clone().requires_grad_(true), zg = z_g0.clone().requires_grad_(true);
    at::Tensor rot = model.decode(frames, zl, zg);
    if (!w.defined()) w = at::randn(rot.sizes());
    (rot * w).sum().backward();
    *g_zl = zl.grad();
    *g_zg = zg.grad();
    return rot.detach();
  };
  at::Tensor module_zl, module_zg;
  const at::Tensor module = decode(&module_zl, &module_zg);
  const float scale = module_zl.abs().max().item<float>();
  ASSERT_GT(scale, 1e-2f);
  model.set_requires_grad(false);
  const int threads = at::get_num_threads();
  for (int t : {1, 2}) {  // whole, then in two halves on two threads
    SCOPED_TRACE(t);
    at::set_num_threads(t);
    at::Tensor node_zl, node_zg;
    const at::Tensor node = decode(&node_zl, &node_zg);
    EXPECT_LT((node - module).abs().max().item<float>(), 1e-5);
    EXPECT_LT((node_zl - module_zl).abs().max().item<float>(), 1e-4 * scale);
    EXPECT_LT((node_zg - module_zg).abs().max().item<float>(), 1e-4 * module_zg.abs().max().item<float>());
    at::NoGradGuard no_grad;  // the same node without recording
    EXPECT_LT((model.decode(frames, z_l0, z_g0) - module).abs().max().item<float>(), 1e-5);
    EXPECT_LT((model.decode(frames.narrow(0, 0, 20), z_l0, z_g0) - module.narrow(1, 0, 20)).abs().max().item<float>(),
              1e-5);  // always whole
  }
  at::set_num_threads(threads);
}

TEST(PriorModel, FrozenGmpNodeMatchesTheModulePath) {
  // A frozen GMP runs one window through one hand-written autograd node (in
  // two halves with halos from 64 frames up on two threads); outputs and input
  // gradients must be the module path's at every length, on one thread or two.
  at::manual_seed(6);
  RigInfo rig = tiny_rig();
  NemfConfig config = tiny_nemf_config();
  config.gmp_blocks = 2;
  config.gmp_kernel = 5;
  NemfModel model(config, rig);
  const int C = rig.num_joints() * 3 + 6;
  for (int T : {3, 20, 64, 101}) {
    SCOPED_TRACE(T);
    const at::Tensor inputs = at::randn({1, T, C});
    const at::Tensor w = at::randn({1, T, 4 + rig.num_feet()});
    auto run = [&](at::Tensor* grad) {
      at::Tensor x = inputs.clone().requires_grad_(true);
      GmpOutput g = model.predict_global_from_inputs(x);
      at::Tensor out = at::cat({g.velocity, g.height, g.contact_logits}, -1);
      (out * w).sum().backward();
      *grad = x.grad();
      return out.detach();
    };
    model.set_requires_grad(true);
    at::Tensor module_grad;
    const at::Tensor module = run(&module_grad);
    const float scale = module.abs().max().item<float>(), grad_scale = module_grad.abs().max().item<float>();
    ASSERT_GT(grad_scale, 1e-3f);
    model.set_requires_grad(false);
    const int threads = at::get_num_threads();
    for (int t : {1, 2}) {  // whole, then in halves from 64 frames on two threads
      SCOPED_TRACE(t);
      at::set_num_threads(t);
      at::Tensor node_grad;
      const at::Tensor node = run(&node_grad);
      EXPECT_LT((node - module).abs().max().item<float>(), 1e-5 * scale + 1e-6);
      EXPECT_LT((node_grad - module_grad).abs().max().item<float>(), 1e-5 * grad_scale);
    }
    at::set_num_threads(threads);
  }
}

TEST(PriorModel, FrozenEncoderMatchesUnfrozenAndHonoursLaterWeightEdits) {
  // Freezing masks the skeleton convolutions' weights once; the encode must not
  // change, and an in-place edit of a weight afterwards must reach it, masked.
  at::manual_seed(0);
  RigInfo rig = tiny_rig();
  NemfModel model(tiny_nemf_config(), rig);
  Motion m = test::random_motion(rig.skeleton, 32, 30.0, 2);
  WindowTensors w = window_tensors(m, 0, 32, rig, 0);
  const at::Tensor mask = at::ones({1, 32});
  auto encode = [&] {
    at::NoGradGuard no_grad;
    return model.encode(w.local_rotations, mask).mu_l;
  };
  const at::Tensor unfrozen = encode();
  model.set_requires_grad(false);
  EXPECT_TRUE(at::equal(encode(), unfrozen));

  at::Tensor weight;
  for (auto& [name, p] : model.named_parameters()) {
    if (name == "local_encoder.conv0.weight") weight = p;
  }
  ASSERT_TRUE(weight.defined());
  {
    at::NoGradGuard no_grad;
    weight.add_(0.1);  // also into the entries the mask zeroes
  }
  const at::Tensor edited_frozen = encode();
  EXPECT_FALSE(at::allclose(edited_frozen, unfrozen));
  model.set_requires_grad(true);
  EXPECT_TRUE(at::equal(edited_frozen, encode()));
  model.set_requires_grad(false);  // masks the edited weights again
  EXPECT_TRUE(at::equal(edited_frozen, encode()));
}

class ModelFile : public ::testing::Test {
 protected:
  void SetUp() override {
    at::manual_seed(0);
    // One folder per test: CTest runs this fixture's tests in parallel processes.
    dir_ = test::scratch_dir(std::string("model_file-") +
                             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    path_ = dir_ + "/m.mfm";
    NemfModel model(tiny_nemf_config(), tiny_rig());
    save_nemf(model, path_);
    bytes_ = serialize_nemf(model);
  }
  std::string error_of(const std::vector<uint8_t>& b) {
    try {
      deserialize_nemf(b.data(), b.size(), "x.mfm");
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
  std::string dir_, path_;
  std::vector<uint8_t> bytes_;
};

TEST_F(ModelFile, RoundTripGivesTheSameOutputs) {
  at::manual_seed(0);
  NemfModel a(tiny_nemf_config(), tiny_rig());
  a.stats().feature_mean.fill_(0.25);
  save_nemf(a, path_);
  NemfModel b = load_nemf(path_);
  EXPECT_EQ(b.config().to_map(), a.config().to_map());
  EXPECT_TRUE(b.rig().skeleton.same_as(a.rig().skeleton));
  EXPECT_EQ(b.rig().foot_joints, a.rig().foot_joints);
  EXPECT_TRUE(at::equal(b.stats().feature_mean, a.stats().feature_mean));
  at::Tensor z = at::randn({1, 8}), g = at::randn({1, 4}), t = at::arange(0, 32, at::kFloat);
  EXPECT_TRUE(at::allclose(a.decode(t, z, g), b.decode(t, z, g)));
}

TEST_F(ModelFile, ErrorsSayWhatIsWrong) {
  std::vector<uint8_t> b = bytes_;
  b[0] = 'X';
  EXPECT_NE(error_of(b).find("not a motionfield model file"), std::string::npos);
  b = bytes_;
  b[8] = 99;  // format version
  EXPECT_NE(error_of(b).find("unsupported model format version 99"), std::string::npos);
  b = bytes_;
  b[16] = 'x';  // kind "nemf" -> "xemf" (after the u32 length at 12..15)
  EXPECT_NE(error_of(b).find("wrong kind of model"), std::string::npos);
  b = bytes_;
  b.resize(b.size() / 2);
  EXPECT_NE(error_of(b).find("truncated"), std::string::npos);
  b = bytes_;
  b[b.size() / 2] ^= 0x5a;
  EXPECT_NE(error_of(b).find("checksum"), std::string::npos);
  EXPECT_NE(error_of({}).find("not a motionfield model file"), std::string::npos);
  EXPECT_THROW(load_nemf(dir_ + "/missing.mfm"), InputError);
}

TEST_F(ModelFile, SteeringGmpIsStoredAndChosenByUse) {
  NemfConfig c = tiny_nemf_config();
  c.steering_gmp = 1;
  at::manual_seed(1);
  NemfModel a(c, tiny_rig());
  ASSERT_TRUE(a.has_steering_gmp());
  save_nemf(a, path_);
  NemfModel b = load_nemf(path_);
  ASSERT_TRUE(b.has_steering_gmp());
  EXPECT_EQ(b.config().steering_gmp, 1);
  at::Tensor z = at::randn({1, 8}), g = at::randn({1, 4}), t = at::arange(0, 32, at::kFloat);
  const at::Tensor rot = b.decode(t, z, g);
  auto velocity = [&](const NemfModel& m, GmpUse use) { return m.predict_global(rot, use).velocity; };
  EXPECT_TRUE(at::allclose(velocity(a, GmpUse::Steering), velocity(b, GmpUse::Steering)));
  EXPECT_TRUE(at::allclose(velocity(a, GmpUse::Default), velocity(b, GmpUse::Default)));
  EXPECT_FALSE(at::allclose(velocity(b, GmpUse::Default), velocity(b, GmpUse::Steering)));  // two GMPs
  // Neither the VAE's nor the default GMP's parameters include it.
  NemfModel plain(tiny_nemf_config(), tiny_rig());
  EXPECT_EQ(b.vae_parameters().size(), plain.vae_parameters().size());
  EXPECT_EQ(b.gmp_parameters().size(), plain.gmp_parameters().size());
  EXPECT_GT(b.parameters().size(), plain.parameters().size());
  // Without one, Steering is the default GMP, and files do not carry the key.
  EXPECT_FALSE(plain.has_steering_gmp());
  EXPECT_TRUE(at::equal(velocity(plain, GmpUse::Steering), velocity(plain, GmpUse::Default)));
  EXPECT_EQ(plain.config().to_map().count("steering_gmp"), 0u);
  EXPECT_EQ(load_nemf(path_).config().to_map().at("steering_gmp"), 1.0);
  c.steering_gmp = 2;
  EXPECT_NE(c.validate(), "");
}

// Found by fuzz_model_file: hyperparameters outside int's range were cast
// (undefined), and the GMP's width had no upper bound (2e9 asked for 200 GB).
TEST(PriorModel, HyperparametersAreBoundedBeforeTheNetworkIsBuilt) {
  std::map<std::string, double> values = tiny_nemf_config().to_map();
  for (double bad : {1e300, -1e300, std::nan(""), 0.5}) {
    std::map<std::string, double> v = values;
    v["window"] = bad;
    EXPECT_THROW(NemfConfig::from_map(v), InputError) << bad;
  }
  NemfConfig c = tiny_nemf_config();
  c.gmp_width = 2000000000;
  EXPECT_NE(c.validate(), "");
  c = tiny_nemf_config();
  c.window = 1 << 20;
  EXPECT_NE(c.validate(), "");
  EXPECT_EQ(tiny_nemf_config().validate(), "");
}

TEST(PriorTraining, AFewStepsRunCheckpointAndResume) {
  namespace fs = std::filesystem;
  std::string dir = test::scratch_dir("prior_training");
  Skeleton s = test::small_skeleton();
  for (int i = 0; i < 12; ++i) {
    Motion m = test::random_motion(s, 20 + 7 * i, 30.0, 100 + i);
    write_motion(dir + "/clip" + std::to_string(i) + ".bvh", m, default_bvh_layout(s));
  }
  PriorTrainingOptions o;
  o.data = dir;
  o.cache_dir = dir + "/cache";
  o.out_dir = dir + "/run";
  o.config = tiny_nemf_config();
  o.batch = 4;
  o.stride = 16;
  o.max_epochs = 2;
  o.verbose = false;
  PriorTrainingResult r = train_prior(o);
  EXPECT_EQ(r.epochs, 2);
  EXPECT_GT(r.steps, 0);
  EXPECT_TRUE(fs::exists(o.out_dir + "/best.mfm"));
  EXPECT_TRUE(fs::exists(o.out_dir + "/log.csv"));
  o.resume = true;
  o.max_epochs = 3;
  PriorTrainingResult r2 = train_prior(o);
  EXPECT_EQ(r2.epochs, 3);
  EXPECT_GT(r2.steps, r.steps);
  NemfModel m = load_nemf(r2.best_path);
  EXPECT_EQ(m.config().zl, 8);

  // --init: a new run starts from that model's weights and statistics (with a
  // zero learning rate they come out unchanged), not from random ones.
  PriorTrainingOptions f = o;
  f.resume = false;
  f.init_from = r2.best_path;
  f.out_dir = dir + "/finetune";
  f.max_epochs = 1;
  f.lr = f.lr_final = 0.0;
  train_prior(f);
  NemfModel tuned = load_nemf(f.out_dir + "/last.mfm");
  std::vector<at::Tensor> a = m.parameters(), b = tuned.parameters();
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(at::equal(a[i], b[i])) << "parameter " << i;
  EXPECT_TRUE(at::equal(m.stats().feature_mean, tuned.stats().feature_mean));
  EXPECT_TRUE(at::equal(m.stats().gmp_out_std, tuned.stats().gmp_out_std));

  // --gmp-only: a new GMP of other sizes on --init's frozen VAE and statistics.
  PriorTrainingOptions g = f;
  g.out_dir = dir + "/gmp-only";
  g.gmp_only = true;
  g.config.gmp_width = 12;
  g.config.gmp_blocks = 2;
  g.lr = g.lr_final = 1e-2;
  train_prior(g);
  NemfModel regrown = load_nemf(g.out_dir + "/last.mfm");
  EXPECT_EQ(regrown.config().gmp_width, 12);
  EXPECT_EQ(regrown.config().gmp_blocks, 2);
  std::vector<at::Tensor> vae_a = m.vae_parameters(), vae_b = regrown.vae_parameters();
  ASSERT_EQ(vae_a.size(), vae_b.size());
  for (size_t i = 0; i < vae_a.size(); ++i) EXPECT_TRUE(at::equal(vae_a[i], vae_b[i])) << "VAE parameter " << i;
  EXPECT_TRUE(at::equal(m.stats().gmp_in_mean, regrown.stats().gmp_in_mean));
  EXPECT_EQ(regrown.gmp_parameters()[0].size(0), 12);
  // It is trained: the GMP's weights move off their initial values over a second run.
  PriorTrainingOptions g2 = g;
  g2.resume = true;
  g2.max_epochs = 2;
  train_prior(g2);
  std::vector<at::Tensor> before = regrown.gmp_parameters(), after = load_nemf(g.out_dir + "/last.mfm").gmp_parameters();
  bool moved = false;
  for (size_t i = 0; i < before.size(); ++i) moved = moved || !at::equal(before[i], after[i]);
  EXPECT_TRUE(moved);
  // With the same GMP sizes --init's GMP is kept (here with a zero learning
  // rate: unchanged), and its inputs can come from the VAE's reconstruction.
  PriorTrainingOptions keep = g;
  keep.out_dir = dir + "/gmp-keep";
  keep.init_from = g.out_dir + "/last.mfm";
  keep.lr = keep.lr_final = 0.0;
  keep.gmp_reconstructed = 0.5;
  keep.max_epochs = 1;
  train_prior(keep);
  std::vector<at::Tensor> kept = load_nemf(keep.out_dir + "/last.mfm").gmp_parameters();
  ASSERT_EQ(kept.size(), after.size());
  for (size_t i = 0; i < kept.size(); ++i) EXPECT_TRUE(at::equal(kept[i], after[i])) << "GMP parameter " << i;
  // The same GMP on the same windows with captured inputs only has other losses.
  PriorTrainingOptions captured = keep;
  captured.out_dir = dir + "/gmp-captured";
  captured.gmp_reconstructed = 0.0;
  train_prior(captured);
  auto gmp_losses = [](const std::string& log_path) {  // the last epoch's
    std::vector<double> out;
    for (const char* column : {"train_vel", "train_height", "train_trans", "train_contact"}) {
      const std::vector<double> values = test::log_column(log_path, column);
      EXPECT_FALSE(values.empty()) << column;
      out.push_back(values.empty() ? 0.0 : values.back());
    }
    return out;
  };
  EXPECT_NE(gmp_losses(keep.out_dir + "/log.csv"), gmp_losses(captured.out_dir + "/log.csv"));
  // --steering-gmp: --init's GMP is kept, frozen, as the steering GMP and the
  // default GMP is the one trained; the sizes must be --init's.
  PriorTrainingOptions steer = keep;
  steer.out_dir = dir + "/gmp-steer";
  steer.config.steering_gmp = 1;
  steer.lr = steer.lr_final = 1e-2;
  train_prior(steer);
  NemfModel steered = load_nemf(steer.out_dir + "/last.mfm");
  ASSERT_TRUE(steered.has_steering_gmp());
  std::map<std::string, at::Tensor> init_params, steered_params;
  for (const auto& [name, value] : load_nemf(keep.init_from).named_parameters()) init_params[name] = value;
  for (const auto& [name, value] : steered.named_parameters()) steered_params[name] = value;
  bool default_moved = false;
  int steering_count = 0;
  for (const auto& [name, value] : init_params) {
    if (name.rfind("gmp.", 0) != 0) continue;
    EXPECT_TRUE(at::equal(steered_params.at("steering_" + name), value)) << name;
    default_moved = default_moved || !at::equal(steered_params.at(name), value);
    ++steering_count;
  }
  EXPECT_GT(steering_count, 0);
  EXPECT_TRUE(default_moved);
  PriorTrainingOptions steer_resume = steer;  // the checkpoint carries the steering GMP
  steer_resume.resume = true;
  steer_resume.max_epochs = 2;
  EXPECT_NO_THROW(train_prior(steer_resume));
  // A VAE run from a model with a steering GMP (a shipped prior) drops it and
  // continues with it as the GMP: it is the one trained with the VAE.
  PriorTrainingOptions vae_from_steered = keep;
  vae_from_steered.out_dir = dir + "/vae-from-steered";
  vae_from_steered.gmp_only = false;
  vae_from_steered.gmp_reconstructed = 0.0;
  vae_from_steered.init_from = steer.out_dir + "/last.mfm";
  vae_from_steered.max_steps = 0;
  vae_from_steered.max_epochs = 1;
  vae_from_steered.lr = vae_from_steered.lr_final = 0.0;
  train_prior(vae_from_steered);
  const NemfModel continued = load_nemf(vae_from_steered.out_dir + "/last.mfm");
  EXPECT_FALSE(continued.has_steering_gmp());
  std::map<std::string, at::Tensor> continued_params;
  for (const auto& [name, value] : continued.named_parameters()) continued_params[name] = value;
  for (const auto& [name, value] : init_params) {
    if (name.rfind("gmp.", 0) != 0) continue;
    EXPECT_TRUE(at::equal(continued_params.at(name), steered_params.at("steering_" + name))) << name;
  }
  PriorTrainingOptions bad_steer = steer;
  bad_steer.out_dir = dir + "/gmp-steer-bad";
  bad_steer.config.gmp_width = 16;
  EXPECT_THROW(train_prior(bad_steer), InputError);
  bad_steer.config.gmp_width = steer.config.gmp_width;
  bad_steer.gmp_only = false;
  EXPECT_THROW(train_prior(bad_steer), InputError);
  PriorTrainingOptions bad_share = keep;
  bad_share.gmp_reconstructed = 1.5;
  EXPECT_THROW(train_prior(bad_share), InputError);
  bad_share.gmp_reconstructed = 0.5;
  bad_share.gmp_only = false;
  EXPECT_THROW(train_prior(bad_share), InputError);

  // Other VAE sizes, or no model to start from, are refused.
  PriorTrainingOptions bad_vae = g;
  bad_vae.out_dir = dir + "/gmp-only-bad";
  bad_vae.config.zl = 16;
  EXPECT_THROW(train_prior(bad_vae), InputError);
  bad_vae.config.zl = g.config.zl;
  bad_vae.init_from.clear();
  EXPECT_THROW(train_prior(bad_vae), InputError);

  // Other sizes, or data on another skeleton, are refused before training.
  PriorTrainingOptions other_size = f;
  other_size.out_dir = dir + "/other-size";
  other_size.config.zl = 16;
  EXPECT_THROW(train_prior(other_size), InputError);
  std::string renamed = dir + "/renamed";
  fs::create_directories(renamed);
  Skeleton t = s;
  t.names[1] = "SomethingElse";
  for (int i = 0; i < 4; ++i) {
    write_motion(renamed + "/clip" + std::to_string(i) + ".bvh", test::random_motion(t, 40, 30.0, 200 + i),
                 default_bvh_layout(t));
  }
  PriorTrainingOptions other_rig = f;
  other_rig.data = renamed;
  other_rig.cache_dir = renamed + "/cache";
  other_rig.out_dir = dir + "/other-rig";
  try {
    train_prior(other_rig);
    ADD_FAILURE() << "a prior on another skeleton was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("another skeleton"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mf
