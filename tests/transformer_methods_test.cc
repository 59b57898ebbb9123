// The transformer methods ("context", "detail", "citl"), their fill
// (inbetweener_fill) and the transformer initialisers, with a stand-in model:
// a test-only InbetweenerRuntime that interpolates the known pose features
// linearly per channel (stage 1 = stage 0 moved 1 cm along canonical x and
// joint 1 turned a little at unknown values; optionally every output 5 cm
// off), and
// records what it was given. No trained file is needed.
#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "prior/inbetween/inbetweener_kinds.h"
#include "prior/model/nemf.h"
#include "prior/runtime/inbetween_runtime.h"
#include "prior/motion/errors.h"
#include "tasks/constraints/interpolation_fill.h"
#include "tasks/constraints/seams.h"
#include "tasks/transformer/inbetweener_fill.h"
#include "tasks/latent/initializers.h"
#include "tasks/methods/jobs.h"
#include "tasks/methods/transformer_methods.h"
#include "tasks/transformer/inbetweener_files.h"
#include "tests/runtime_test_util.h"
#include "tests/test_util.h"

namespace mf {
namespace {

class LinearInbetweener : public runtime::InbetweenerRuntime {
 public:
  LinearInbetweener(const RigInfo& rig, std::string kind, int window)
      : InbetweenerRuntime(rig, identity_normalisation(rig)), kind_(std::move(kind)), window_(window) {}

  std::string kind() const override { return kind_; }
  std::vector<std::string> stage_names() const override {
    return kind_ == kTwoStageKind ? std::vector<std::string>{"context", "detail"} : std::vector<std::string>{"citl"};
  }
  int window() const override { return window_; }
  double fps() const override { return 30.0; }

  void forward(const runtime::InbetweenWindow& in, runtime::InbetweenResult* result) const override {
    const int J = rig().num_joints(), D = pose_size();
    const int T = static_cast<int>(in.pose.rows());
    EXPECT_EQ(in.pose.cols(), D);
    EXPECT_EQ(in.known.rows(), T);
    EXPECT_EQ(in.known.cols(), J + 1);
    EXPECT_EQ(in.valid.size(), T);
    ++calls;
    max_frames = std::max(max_frames, T);
    known.push_back(in.known);
    runtime::MatrixRXf mask(T, D);
    for (int j = 0; j < J; ++j) mask.middleCols(6 * j, 6) = in.known.col(j).replicate(1, 6);
    mask.rightCols(3) = in.known.col(J).replicate(1, 3);
    unknown_abs_sum += (in.pose.array() * (1 - mask.array())).abs().sum();
    int frames = 0;
    while (frames < T && in.valid[frames] > 0.5f) ++frames;
    // The contract: windows are canonical at a known first frame and end at one.
    for (int j = 0; j <= J; ++j) EXPECT_EQ(in.known(0, j), 1.0f) << "a window does not start at a full key";
    EXPECT_EQ(in.known(frames - 1, J), 1.0f) << "a window does not end at a key";
    runtime::MatrixRXf out = runtime::MatrixRXf::Zero(T, D);
    for (int d = 0; d < D; ++d) {
      std::vector<int> at_known;
      for (int t = 0; t < frames; ++t)
        if (mask(t, d) > 0.5f) at_known.push_back(t);
      for (int t = 0; t < frames; ++t) {
        auto it = std::lower_bound(at_known.begin(), at_known.end(), t);
        if (it == at_known.end()) {
          out(t, d) = in.pose(at_known.back(), d);
        } else if (*it == t || it == at_known.begin()) {
          out(t, d) = in.pose(*it, d);
        } else {
          const int a = *(it - 1), c = *it;
          const float w = static_cast<float>(t - a) / static_cast<float>(c - a);
          out(t, d) = in.pose(a, d) * (1 - w) + in.pose(c, d) * w;
        }
      }
    }
    if (miss_keys) out.col(D - 3).array() += 0.05f;  // misses even the keys by 5 cm
    *result = runtime::InbetweenResult();
    result->stages.push_back(out);
    if (kind_ == kTwoStageKind) {
      runtime::MatrixRXf moved = out;
      const Eigen::ArrayXf root_unknown = 1 - in.known.col(J).array();
      moved.col(D - 3).array() += 0.01f * root_unknown;
      moved.col(6).array() += 0.05f * (1 - in.known.col(1).array());  // joint 1's 6D
      if (jump_off_keys != 0.0) moved.col(D - 3).array() += static_cast<float>(jump_off_keys) * root_unknown;
      result->stages.push_back(moved);
    }
  }

  mutable int calls = 0;
  mutable int max_frames = 0;
  mutable double unknown_abs_sum = 0.0;
  mutable std::vector<runtime::MatrixRXf> known;  // each window's known mask, in call order
  bool miss_keys = false;
  double jump_off_keys = 0.0;  // the two-stage's last stage: the root moved by this much (m) at unknown frames

 private:
  static runtime::InbetweenNormalisation identity_normalisation(const RigInfo& rig) {
    const int D = rig.num_joints() * 6 + 3;
    return {runtime::RowVectorXf::Zero(D), runtime::RowVectorXf::Ones(D)};
  }
  std::string kind_;
  int window_;
};

struct Fixture {
  std::shared_ptr<const runtime::NemfRuntime> prior;
  std::shared_ptr<LinearInbetweener> twostage, citl;
  TaskContext ctx;

  explicit Fixture(int window = 32) {
    const RigInfo rig = test::tiny_rig();
    prior = test::shared_runtime_of(NemfModel(test::tiny_nemf_config(), rig));
    twostage = std::make_shared<LinearInbetweener>(rig, kTwoStageKind, window);
    citl = std::make_shared<LinearInbetweener>(rig, kCitlKind, window);
    ctx.model = prior;
    ctx.add_inbetweener(twostage);
    ctx.add_inbetweener(citl);
  }
  Motion motion(int frames, uint32_t seed = 3) const {
    return test::random_motion(prior->rig().skeleton, frames, 30.0, seed);
  }
};

bool same_motion(const Motion& a, const Motion& b) {
  if (a.num_frames() != b.num_frames() || a.num_joints() != b.num_joints()) return false;
  for (size_t i = 0; i < a.rotations.size(); ++i) {
    if (a.rotations[i].coeffs() != b.rotations[i].coeffs()) return false;
  }
  for (size_t i = 0; i < a.root_positions.size(); ++i) {
    if (a.root_positions[i] != b.root_positions[i]) return false;
  }
  return true;
}

void expect_known_exact(const Motion& in, const Motion& out, const std::vector<int>& known) {
  for (int f : known) {
    for (int j = 0; j < in.num_joints(); ++j) {
      EXPECT_EQ(out.rotation(f, j).coeffs(), in.rotation(f, j).coeffs()) << "frame " << f << " joint " << j;
    }
    EXPECT_EQ(out.root_positions[f], in.root_positions[f]) << "frame " << f;
  }
}

void expect_finite(const Motion& m) {
  for (const auto& q : m.rotations) EXPECT_TRUE(q.coeffs().allFinite());
  for (const auto& p : m.root_positions) EXPECT_TRUE(p.allFinite());
}

TEST(TransformerMethods, RegisteredWithTheirNeedsAndTheDefault) {
  for (const char* name : {"context", "detail", "citl", "nemf-context", "nemf-detail", "nemf-citl"}) {
    const auto& all = registered_methods();
    auto it = std::find_if(all.begin(), all.end(), [&](const Method& m) { return m.name == name; });
    ASSERT_NE(it, all.end()) << name;
    EXPECT_TRUE(it->needs_model) << name;
    EXPECT_TRUE(static_cast<bool>(it->complete)) << name;
    EXPECT_FALSE(static_cast<bool>(it->resample)) << name;
    EXPECT_EQ(it->needs_inbetweener, std::string(name).find("citl") != std::string::npos ? "citl" : "twostage");
  }
  // The default (measured, docs/BENCHMARKS.md): the solver from the two-stage
  // transformer when it is loaded, else from interpolation.
  Fixture fx;
  EXPECT_EQ(default_method(fx.ctx), "nemf-detail");
  TaskContext prior_only = fx.ctx;
  prior_only.inbetweeners.erase(kTwoStageKind);
  EXPECT_EQ(default_method(prior_only), "nemf");
  prior_only.inbetweeners.clear();
  EXPECT_EQ(default_method(prior_only), "nemf");
}

// Every stage of every in-betweener kind in the registry is a one-pass
// method, a solver start ("nemf-<stage>") and an initialiser
// ("<stage>-encoder"), all needing that kind.
TEST(TransformerMethods, EveryKindsStagesBecomeMethodsAndInitialisers) {
  ASSERT_EQ(inbetweener_kinds().size(), 3u);
  const std::vector<std::string> inits = initializer_names();
  int stages = 0;
  for (const InbetweenerKind& kind : inbetweener_kinds()) {
    EXPECT_EQ(inbetweener_file_name(kind.name), "motionfield-" + kind.name + ".mfm");
    for (const InbetweenerStage& stage : kind.stages) {
      ++stages;
      for (const std::string& name : {stage.name, "nemf-" + stage.name}) {
        const Method* found = nullptr;
        for (const Method& m : registered_methods()) found = m.name == name ? &m : found;
        ASSERT_NE(found, nullptr) << name;
        EXPECT_EQ(found->needs_inbetweener, kind.name) << name;
        EXPECT_TRUE(found->needs_model) << name;
      }
      EXPECT_NE(std::find(inits.begin(), inits.end(), stage.name + "-encoder"), inits.end()) << stage.name;
    }
  }
  EXPECT_EQ(stages, 5);
  EXPECT_EQ(find_inbetweener_stage("detail")->name, kTwoStageKind);
  EXPECT_EQ(find_inbetweener_stage("refine")->name, kKeyframeKind);
  EXPECT_EQ(find_inbetweener_stage("nemf"), nullptr);
  EXPECT_THROW(inbetweener_kind("keyframenet"), InputError);
}

// A kind whose file next to the prior did not load: the missing-model error
// is typed (the C API's model status) and quotes why.
TEST(TransformerMethods, MissingModelQuotesWhyItsFileDidNotLoad) {
  Fixture fx;
  TaskContext ctx;
  ctx.model = fx.prior;
  ctx.inbetweener_errors[kCitlKind] = "motionfield-citl.mfm: truncated";
  try {
    run_inbetween(fx.motion(20), {0, 10, 19}, "citl", ctx);
    FAIL() << "no error";
  } catch (const ModelMissingError& e) {
    EXPECT_NE(std::string(e.what()).find("did not load: motionfield-citl.mfm: truncated"), std::string::npos)
        << e.what();
  }
  ctx.add_inbetweener(fx.citl);
  EXPECT_EQ(ctx.inbetweener_errors.count(kCitlKind), 0u);
  EXPECT_NO_THROW(run_inbetween(fx.motion(20), {0, 10, 19}, "citl", ctx));
}

TEST(TransformerMethods, MissingModelNamesTheFile) {
  Fixture fx;
  TaskContext no_transformers;
  no_transformers.model = fx.prior;
  const Motion m = fx.motion(20);
  try {
    run_inbetween(m, {0, 10, 19}, "citl", no_transformers);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("method 'citl' needs models/motionfield-citl.mfm"), std::string::npos)
        << e.what();
  }
  for (const char* method : {"context", "detail", "nemf-detail"}) {
    try {
      run_fill(m, 5, 15, method, no_transformers);
      FAIL() << "no error for " << method;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("motionfield-twostage.mfm"), std::string::npos) << e.what();
    }
  }
  // The method itself checks too (callers that bypass jobs.h).
  for (const Method& method : transformer_methods()) {
    EXPECT_THROW(method.complete(m, {0, 19}, no_transformers, nullptr), InputError) << method.name;
  }
  EXPECT_THROW(make_initializer("citl-encoder", no_transformers), InputError);
  EXPECT_THROW(make_initializer("nope", fx.ctx), InputError);
}

TEST(TransformerMethods, DispatchToStagesKnownFramesExactAndGapsFilled) {
  Fixture fx;
  const Motion in = fx.motion(30);
  const std::vector<int> keys = {0, 9, 21, 29};
  const Motion context = run_inbetween(in, keys, "context", fx.ctx);
  const Motion detail = run_inbetween(in, keys, "detail", fx.ctx);
  const Motion citl = run_inbetween(in, keys, "citl", fx.ctx);
  const Motion interp = interpolate_motion(in, keys);
  EXPECT_EQ(fx.twostage->calls, 2);
  EXPECT_EQ(fx.citl->calls, 1);
  for (const Motion* out : {&context, &detail, &citl}) {
    ASSERT_EQ(out->num_frames(), in.num_frames());
    EXPECT_EQ(out->fps, in.fps);
    expect_known_exact(in, *out, keys);
    expect_finite(*out);
  }
  // The stand-in's stage 0 is linear interpolation in the canonical frame, so
  // the root path is interpolation's; stage 1 is moved by 1 cm off the keys.
  for (int f = 0; f < in.num_frames(); ++f) {
    EXPECT_LT((context.root_positions[f] - interp.root_positions[f]).norm(), 1e-4) << f;
    EXPECT_LT((citl.root_positions[f] - interp.root_positions[f]).norm(), 1e-4) << f;
    const bool key = std::find(keys.begin(), keys.end(), f) != keys.end();
    EXPECT_NEAR((detail.root_positions[f] - context.root_positions[f]).norm(), key ? 0.0 : 0.01, 1e-4) << f;
  }
  // Unknown pose values reach the model as zeros.
  EXPECT_EQ(fx.twostage->unknown_abs_sum, 0.0);
  // Deterministic.
  EXPECT_TRUE(same_motion(detail, run_inbetween(in, keys, "detail", fx.ctx)));
}

TEST(TransformerMethods, UnknownFramesAreNeverRead) {
  Fixture fx;
  const Motion in = fx.motion(32, 5);
  const std::vector<int> known = {0, 1, 2, 3, 4, 20, 31};
  Motion poisoned = in;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int f = 0; f < in.num_frames(); ++f) {
    if (std::find(known.begin(), known.end(), f) != known.end()) continue;
    for (int j = 0; j < in.num_joints(); ++j) poisoned.rotation(f, j) = Eigen::Quaterniond(nan, 0.3, nan, 1.0);
    poisoned.root_positions[f] = Eigen::Vector3d(nan, 7.0, -3.0);
  }
  for (const char* method : {"context", "detail", "citl"}) {
    const Motion a = run_known_frames(in, known, method, fx.ctx);
    const Motion b = run_known_frames(poisoned, known, method, fx.ctx);
    EXPECT_TRUE(same_motion(a, b)) << method;
    expect_finite(b);
  }
}

TEST(TransformerMethods, LongInputsInWindowsThatStartAndEndAtKeys) {
  Fixture fx(24);
  const Motion in = fx.motion(200, 8);
  std::vector<int> keys;
  for (int f = 0; f < 200; f += 7) keys.push_back(f);
  keys.push_back(199);
  const Motion out = run_inbetween(in, keys, "citl", fx.ctx);
  EXPECT_GE(fx.citl->calls, 200 / 24);  // one pass per window
  EXPECT_EQ(fx.citl->known.size(), static_cast<size_t>(fx.citl->calls));
  EXPECT_LE(fx.citl->max_frames, 24);
  expect_known_exact(in, out, keys);
  expect_finite(out);
  const Motion interp = interpolate_motion(in, keys);
  for (int f = 0; f < 200; ++f) EXPECT_LT((out.root_positions[f] - interp.root_positions[f]).norm(), 1e-4) << f;

  // Gap filling on a long clip: frames before and after held like interp.
  const Motion filled = run_fill(in, 120, 140, "detail", fx.ctx);
  expect_known_exact(in, filled, known_frames_outside_gap(200, 120, 140));

  // Keys further apart than the window: a clear error.
  try {
    run_inbetween(in, {0, 10, 60}, "context", fx.ctx);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("keys 10 and 60 are 50 frames apart"), std::string::npos) << e.what();
  }
}

TEST(TransformerMethods, ResidualAtTheKeysIsSpreadOverTheGap) {
  Fixture fx;
  fx.citl->miss_keys = true;  // the model's output is 5 cm off everywhere, keys included
  const Motion in = fx.motion(30, 10);
  const std::vector<int> keys = {0, 9, 21, 29};
  const Motion out = run_inbetween(in, keys, "citl", fx.ctx);
  const Motion interp = interpolate_motion(in, keys);
  expect_known_exact(in, out, keys);
  // A constant miss is taken back completely: no jump next to the keys.
  for (int f = 0; f < in.num_frames(); ++f)
    EXPECT_LT((out.root_positions[f] - interp.root_positions[f]).norm(), 1e-4) << f;
}

// A run's seam is its jump at the keys beyond the keys' own pace.
TEST(Seams, AJumpAtTheKeysIsMeasuredBeyondTheKeysPace) {
  Fixture fx;
  Motion m = fx.motion(21, 4);
  for (int f = 0; f < 21; ++f) {
    for (int j = 0; j < m.num_joints(); ++j) m.rotation(f, j) = m.rotation(0, j);
    m.root_positions[f] = Eigen::Vector3d(0.01 * f, 0.9, 0.0);  // 1 cm per frame
  }
  std::vector<RunSeam> runs = run_seams(forward_kinematics(m), {0, 10, 20});
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_NEAR(runs[0].key_motion_cm, 10.0, 1e-9);
  EXPECT_NEAR(runs[0].seam_cm, 0.0, 1e-9);
  EXPECT_FALSE(implausible_seam(runs[0]));
  for (int f = 11; f < 20; ++f) m.root_positions[f].z() += 0.12;  // 12 cm off between the keys
  runs = run_seams(forward_kinematics(m), {0, 10, 20});
  EXPECT_NEAR(runs[0].seam_cm, 0.0, 1e-9);
  EXPECT_NEAR(runs[1].seam_cm, std::hypot(1.0, 12.0) - 1.0, 1e-6);
  EXPECT_TRUE(implausible_seam(runs[1]));
  EXPECT_NEAR(seam_excess_cm(m, {0, 10, 20}), runs[1].seam_cm, 1e-12);
  EXPECT_EQ(seam_excess_cm(m, {0, 1, 2}), 0.0);  // no run of unknown frames
  // Keys that barely move: a 2 cm jump is more than 0.3 of their motion.
  EXPECT_TRUE(implausible_seam(RunSeam{0, 10, 1.0, 2.0}));
  EXPECT_FALSE(implausible_seam(RunSeam{0, 10, 30.0, 2.0}));
}

// Where the transformer's output jumps at its keys, the gap is interpolated
// and a sentence says so; --no-fallback (interpolation_fallback false) keeps it.
TEST(TransformerMethods, GapsWhoseOutputJumpsAtTheKeysAreInterpolated) {
  Fixture fx;
  const Motion in = fx.motion(30, 12);
  const std::vector<int> keys = {0, 9, 21, 29};
  const Motion interp = interpolate_motion(in, keys);
  std::vector<std::string> warnings;
  const Motion smooth = inbetweener_fill(*fx.twostage, 1, in, MotionConstraints::full_pose(keys),
                                         LongGapPolicy::Throw, false, {true, &warnings});
  EXPECT_TRUE(warnings.empty());  // the stand-in's 1 cm step is within a body's reach
  EXPECT_GT((smooth.root_positions[15] - interp.root_positions[15]).norm(), 0.005);

  fx.twostage->jump_off_keys = 0.3;
  const Motion kept = inbetweener_fill(*fx.twostage, 1, in, MotionConstraints::full_pose(keys), LongGapPolicy::Throw,
                                       false, {false, &warnings});
  EXPECT_TRUE(warnings.empty());
  EXPECT_GT((kept.root_positions[15] - interp.root_positions[15]).norm(), 0.25);
  const Motion out = inbetweener_fill(*fx.twostage, 1, in, MotionConstraints::full_pose(keys), LongGapPolicy::Throw,
                                      false, {true, &warnings});
  expect_known_exact(in, out, keys);
  for (int f = 0; f < in.num_frames(); ++f) {
    EXPECT_LT((out.root_positions[f] - interp.root_positions[f]).norm(), 1e-9) << f;
    for (int j = 0; j < in.num_joints(); ++j)
      EXPECT_LT(out.rotation(f, j).angularDistance(interp.rotation(f, j)), 1e-9) << f << " " << j;
  }
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("interpolation was used for 3 gap(s)"), std::string::npos) << warnings[0];
  // Through the method, the context's switch decides.
  TaskContext strict = fx.ctx;
  strict.interpolation_fallback = false;
  EXPECT_GT((run_inbetween(in, keys, "detail", strict).root_positions[15] - interp.root_positions[15]).norm(), 0.25);
  EXPECT_LT((run_inbetween(in, keys, "detail", fx.ctx).root_positions[15] - interp.root_positions[15]).norm(), 1e-9);
}

TEST(TransformerMethods, EndsHeldLikeInterpolation) {
  Fixture fx;
  const Motion in = fx.motion(30, 9);
  const std::vector<int> keys = {5, 12, 20};
  const Motion out = run_inbetween(in, keys, "citl", fx.ctx);
  const Motion interp = interpolate_motion(in, keys);
  for (int f : {0, 1, 4, 21, 29}) {
    EXPECT_TRUE(out.root_positions[f] == interp.root_positions[f]) << f;
    for (int j = 0; j < in.num_joints(); ++j) EXPECT_EQ(out.rotation(f, j).coeffs(), interp.rotation(f, j).coeffs());
  }
}

TEST(TransformerMethods, PartialKeysGiveTheirKnownMask) {
  Fixture fx;
  const Motion in = fx.motion(32, 11);
  const int J = in.num_joints();
  MotionConstraints c;
  c.keys.push_back({0, {}, true});
  c.keys.push_back({10, {0}, true});       // root only: fixes the root
  c.keys.push_back({20, {3, 4}, false});   // two joints, no root position
  c.keys.push_back({31, {}, true});
  const Motion out = inbetweener_fill(*fx.citl, -1, in, c, LongGapPolicy::Throw);
  // One window [0, 31], canonical at 0.
  ASSERT_EQ(fx.citl->known.size(), 1u);
  const runtime::MatrixRXf& k = fx.citl->known[0];
  for (int j = 0; j <= J; ++j) {
    EXPECT_EQ(k(10, j), (j == 0 || j == J) ? 1.0f : 0.0f) << j;
    EXPECT_EQ(k(20, j), (j == 3 || j == 4) ? 1.0f : 0.0f) << j;
    EXPECT_EQ(k(15, j), 0.0f) << j;
  }
  EXPECT_EQ(out.rotation(10, 0).coeffs(), in.rotation(10, 0).coeffs());
  EXPECT_EQ(out.root_positions[10], in.root_positions[10]);
  EXPECT_EQ(out.rotation(20, 3).coeffs(), in.rotation(20, 3).coeffs());
  EXPECT_EQ(out.rotation(20, 4).coeffs(), in.rotation(20, 4).coeffs());
  expect_finite(out);
  EXPECT_THROW(inbetweener_fill(*fx.twostage, 2, in, c, LongGapPolicy::Throw), InputError);  // no stage 2
}

TEST(TransformerInitializers, FiniteCodesOfThePriorsShapeFromEachTransformer) {
  Fixture fx;
  const Motion window = fx.motion(32, 13);
  MotionConstraints c;
  c.keys.push_back({0, {}, true});
  c.keys.push_back({12, {1, 2, 5}, false});
  c.keys.push_back({31, {}, true});
  InitRequest r;
  r.model = fx.prior.get();
  r.window = &window;
  r.constraints = &c;
  r.anchor = 0;
  r.context = &fx.ctx;
  const std::vector<std::string> names = initializer_names();
  for (const char* name : {"context-encoder", "detail-encoder", "citl-encoder"}) {
    ASSERT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
    const InitialGuess bound = make_initializer(name, fx.ctx)->initialize(r);
    ASSERT_EQ(bound.z_l.size(), fx.prior->config().zl) << name;
    ASSERT_EQ(bound.z_g.size(), fx.prior->config().zg) << name;
    EXPECT_TRUE(bound.z_l.allFinite()) << name;
    EXPECT_TRUE(bound.z_g.allFinite()) << name;
    const InitialGuess from_context = make_initializer(name)->initialize(r);
    EXPECT_EQ(bound.z_l, from_context.z_l) << name;
  }
  // Detail differs from context (stage 1 vs stage 0).
  EXPECT_NE(make_initializer("context-encoder")->initialize(r).z_l,
            make_initializer("detail-encoder")->initialize(r).z_l);
  // Without a transformer in the request's context: the missing-file error.
  TaskContext bare;
  r.context = &bare;
  EXPECT_THROW(make_initializer("citl-encoder")->initialize(r), InputError);
}

TEST(TransformerInitializers, SolverMethodsStartFromTheTransformer) {
  Fixture fx;
  const Motion in = fx.motion(28, 17);
  const std::vector<int> keys = {0, 10, 27};
  const Motion out = run_inbetween(in, keys, "nemf-citl", fx.ctx);
  EXPECT_GE(fx.citl->calls, 1);
  expect_known_exact(in, out, keys);
  expect_finite(out);
}

}  // namespace
}  // namespace mf
