// The prior as a codec (tasks/latent/prior_codec.h) on tiny random models (on
// the Eigen runtime): window layout, blend weights, shapes at any frame rate,
// short and long clips, the root path's anchoring, and resampling with the
// residual (known frames exact).
#include "tasks/latent/prior_codec.h"

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "prior/runtime/rotations.h"
#include "tasks/methods/jobs.h"
#include "tests/runtime_test_util.h"
#include "tests/test_util.h"

namespace mf {
namespace {

bool all_unit_and_finite(const Motion& m) {
  for (const auto& q : m.rotations) {
    if (!std::isfinite(q.w()) || std::abs(q.norm() - 1.0) > 1e-9) return false;
  }
  for (const auto& p : m.root_positions) {
    if (!p.allFinite()) return false;
  }
  return true;
}

// The tiny prior on the Eigen runtime, built once.
const runtime::NemfRuntime& tiny_runtime() {
  static const runtime::NemfRuntime model = test::runtime_of(test::tiny_prior());
  return model;
}

TEST(PriorCodec, WindowStartsCoverTheClipAndEndAligned) {
  EXPECT_EQ(window_starts(20, 32, 16), (std::vector<int>{0}));
  EXPECT_EQ(window_starts(32, 32, 16), (std::vector<int>{0}));
  EXPECT_EQ(window_starts(33, 32, 16), (std::vector<int>{0, 1}));
  EXPECT_EQ(window_starts(100, 32, 16), (std::vector<int>{0, 16, 32, 48, 64, 68}));
  EXPECT_EQ(window_starts(96, 32, 16), (std::vector<int>{0, 16, 32, 48, 64}));
  EXPECT_THROW(window_starts(100, 32, 32), InputError);
  EXPECT_THROW(window_starts(100, 32, 0), InputError);
  EXPECT_THROW(window_starts(0, 32, 16), InputError);
}

TEST(PriorCodec, BlendWeightsSumToOneAndAreContinuous) {
  std::vector<WindowCode> w;
  for (int s : window_starts(100, 32, 16)) {
    WindowCode c;
    c.start = s;
    c.length = 32;
    w.push_back(c);
  }
  std::vector<double> prev = blend_weights(w, 0.0);
  EXPECT_DOUBLE_EQ(prev[0], 1.0);
  for (double s = 0.0; s <= 99.0; s += 0.125) {
    std::vector<double> cur = blend_weights(w, s);
    double sum = 0.0;
    for (size_t k = 0; k < w.size(); ++k) {
      EXPECT_GE(cur[k], 0.0);
      if (s < w[k].start || s > w[k].start + w[k].length - 1) {
        EXPECT_EQ(cur[k], 0.0) << "s " << s << " k " << k;
      }
      EXPECT_LT(std::abs(cur[k] - prev[k]), 0.05) << "jump at s " << s;  // raised cosine: slope <= pi/2/15 per frame
      sum += cur[k];
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);
    prev = cur;
  }
  EXPECT_DOUBLE_EQ(blend_weights(w, 99.0).back(), 1.0);
  // Two windows overlapping alone: the raised-cosine ramps are complementary.
  std::vector<double> mid = blend_weights(w, 24.0);  // windows 0 [0, 31] and 1 [16, 47]
  EXPECT_NEAR(mid[1], 0.5 - 0.5 * std::cos(M_PI * 8.0 / 15.0), 1e-12);
}

TEST(PriorCodec, EncodeSplitsLongClipsIntoWindows) {
  const runtime::NemfRuntime* model = &tiny_runtime();
  Motion m = test::random_motion(model->rig().skeleton, 100, 30.0, 7);
  EncodedMotion code = encode_motion(*model, m);
  EXPECT_EQ(code.frames, 100);
  ASSERT_EQ(code.windows.size(), 6u);
  const std::vector<int> starts{0, 16, 32, 48, 64, 68};
  for (size_t k = 0; k < starts.size(); ++k) {
    const WindowCode& w = code.windows[k];
    EXPECT_EQ(w.start, starts[k]);
    EXPECT_EQ(w.length, 32);
    EXPECT_EQ(w.z_l.size(), 8);
    EXPECT_EQ(w.z_g.size(), 4);
    GroundTransform g = canonical_transform(m, w.start, model->rig());
    EXPECT_DOUBLE_EQ(w.transform.yaw, g.yaw);
    EXPECT_DOUBLE_EQ(w.transform.x, g.x);
  }
  // The same window encoded on its own gives the same latent: windows are independent.
  const runtime::LatentGaussians z = model->encode_rotations(window_matrices(m, 16, 32, model->rig(), 0).local_rotations);
  EXPECT_LT((z.mu_l - code.windows[1].z_l).cwiseAbs().maxCoeff(), 1e-5);
  // A hop of 8 makes more windows.
  EXPECT_EQ(encode_motion(*model, m, CodecOptions{8}).windows.size(), 10u);
  EXPECT_THROW(encode_motion(*model, m, CodecOptions{32}), InputError);
}

TEST(PriorCodec, ShortClipsAndOtherFrameRatesEncodeAsOneShortWindow) {
  const runtime::NemfRuntime* model = &tiny_runtime();
  const Skeleton& s = model->rig().skeleton;
  EncodedMotion a = encode_motion(*model, test::random_motion(s, 2, 30.0, 1));
  ASSERT_EQ(a.windows.size(), 1u);
  EXPECT_EQ(a.windows[0].length, 2);
  // 61 frames at 60 fps span 1 s: 31 model frames, one short window.
  EncodedMotion b = encode_motion(*model, test::random_motion(s, 61, 60.0, 2));
  EXPECT_EQ(b.frames, 31);
  ASSERT_EQ(b.windows.size(), 1u);
  EXPECT_EQ(b.windows[0].length, 31);
  EXPECT_DOUBLE_EQ(b.source_fps, 60.0);
  // 24 fps, 23 frames: 22/24 s = 27.5 model frames, covered by 29.
  EncodedMotion c = encode_motion(*model, test::random_motion(s, 23, 24.0, 3));
  EXPECT_EQ(c.frames, 29);
  // 15 fps, 40 frames: 79 model frames, several windows.
  EncodedMotion d = encode_motion(*model, test::random_motion(s, 40, 15.0, 4));
  EXPECT_EQ(d.frames, 79);
  EXPECT_EQ(d.windows.size(), 4u);  // window_starts(79, 32, 16) = {0, 16, 32, 47}
}

TEST(PriorCodec, DecodesAtAnyFrameRate) {
  const runtime::NemfRuntime* model = &tiny_runtime();
  Motion m = test::random_motion(model->rig().skeleton, 70, 30.0, 11);
  EncodedMotion code = encode_motion(*model, m);
  for (double fps : {24.0, 30.0, 60.0, 120.0, 240.0}) {
    const int frames = static_cast<int>(std::floor(69 * fps / 30.0 + 1e-9)) + 1;
    Motion out = decode_motion(*model, code, fps, frames);
    EXPECT_EQ(out.num_frames(), frames);
    EXPECT_EQ(out.fps, fps);
    EXPECT_EQ(out.num_joints(), m.num_joints());
    EXPECT_TRUE(all_unit_and_finite(out));
  }
  EXPECT_EQ(decode_motion(*model, code, 30.0, 0).num_frames(), 0);
  EXPECT_THROW(decode_motion(*model, code, 0.0, 10), InputError);
  EXPECT_THROW(decode_motion(*model, code, 30.0, -1), InputError);
  EXPECT_THROW(decode_times(*model, code, {0.0, NAN}, 30.0), InputError);
}

TEST(PriorCodec, SingleWindowDecodeIsTheModelsDecodeInTheWorldFrame) {
  const runtime::NemfRuntime* model = &tiny_runtime();
  Motion m = test::random_motion(model->rig().skeleton, 25, 30.0, 5);
  EncodedMotion code = encode_motion(*model, m);
  ASSERT_EQ(code.windows.size(), 1u);
  const WindowCode& w = code.windows[0];
  std::vector<double> times{0.0, 0.1, 0.35, 24 / 30.0};
  Motion out = decode_times(*model, code, times, 30.0);
  Eigen::VectorXd frames(4);
  frames << 0.0, 3.0, 10.5, 24.0;
  runtime::DecoderWorkspace ws;
  runtime::MatrixRXf sixd, rotations;
  model->decode(frames, w.z_l, w.z_g, &ws, &sixd);
  runtime::sixd_to_matrix(sixd, &rotations);
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(w.transform.yaw, Eigen::Vector3d::UnitY()));
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < m.num_joints(); ++j) {
      const Eigen::Vector4d e = runtime::matrix_to_quat(&rotations(i, j * 9)).cast<double>();
      Eigen::Quaterniond expect(e[0], e[1], e[2], e[3]);
      if (j == 0) expect = turn * expect;
      EXPECT_LT(geodesic_angle(out.rotation(i, j), expect), 1e-5) << "time " << i << " joint " << j;
    }
  }
  // The prior's root path starts at the input's root ground position.
  EXPECT_NEAR(out.root_positions[0].x(), m.root_positions[0].x(), 1e-6);
  EXPECT_NEAR(out.root_positions[0].z(), m.root_positions[0].z(), 1e-6);
}

TEST(PriorCodec, OverlapBlendIsTheWeightedMeanOfTheWindows) {
  const runtime::NemfRuntime* model = &tiny_runtime();
  Motion m = test::random_motion(model->rig().skeleton, 48, 30.0, 8);
  EncodedMotion code = encode_motion(*model, m);  // windows [0, 31] and [16, 47]
  ASSERT_EQ(code.windows.size(), 2u);
  const double s = 21.25;  // inside the overlap
  Motion blended = decode_times(*model, code, {s / 30.0}, 30.0);
  std::vector<double> w = blend_weights(code.windows, s);
  ASSERT_GT(w[0], 0.1);
  ASSERT_GT(w[1], 0.1);
  // Each window alone: a code with that window only, decoded at the same time.
  std::vector<Motion> single;
  for (int k = 0; k < 2; ++k) {
    EncodedMotion one = code;
    one.windows = {code.windows[k]};
    single.push_back(decode_times(*model, one, {s / 30.0}, 30.0));
  }
  for (int j = 0; j < m.num_joints(); ++j) {
    Eigen::Vector4d a = single[0].rotation(0, j).coeffs(), b = single[1].rotation(0, j).coeffs();
    if (a.dot(b) < 0) b = -b;
    Eigen::Vector4d mean = (w[0] * a + w[1] * b).normalized();
    Eigen::Vector4d got = blended.rotation(0, j).coeffs();
    EXPECT_LT(std::min((got - mean).norm(), (got + mean).norm()), 1e-5) << "joint " << j;
  }
  Eigen::Vector3d p = w[0] * single[0].root_positions[0] + w[1] * single[1].root_positions[0];
  EXPECT_LT((blended.root_positions[0] - p).norm(), 1e-5);  // float decodes, batched differently
}

TEST(PriorCodec, InputRootPathIsInterpolated) {
  const runtime::NemfRuntime* model = &tiny_runtime();
  Motion m = test::random_motion(model->rig().skeleton, 20, 15.0, 12);
  EncodedMotion code = encode_motion(*model, m);
  Motion out = decode_motion(*model, code, 30.0, 39, DecodeOptions{RootSource::kInput});
  for (int i = 0; i < 39; ++i) {
    Eigen::Vector3d expect = i % 2 == 0 ? m.root_positions[i / 2]
                                        : Eigen::Vector3d(0.5 * (m.root_positions[i / 2] + m.root_positions[i / 2 + 1]));
    EXPECT_LT((out.root_positions[i] - expect).norm(), 1e-12);
  }
}

TEST(PriorCodec, ResampleKeepsInputFramesExactly) {
  auto model = std::make_shared<const NemfModel>(test::tiny_prior());
  TaskContext ctx = test::context_of(*model);
  const Skeleton& s = model->rig().skeleton;
  struct Case {
    int frames;
    double fps_in, fps_out;
  };
  for (Case c : {Case{20, 15.0, 30.0}, Case{90, 30.0, 60.0}, Case{13, 24.0, 60.0}, Case{61, 60.0, 30.0},
                 Case{2, 15.0, 30.0}, Case{2, 30.0, 30.0}}) {
    Motion m = test::random_motion(s, c.frames, c.fps_in, 21);
    const int out_frames = resampled_frame_count(c.frames, c.fps_in, c.fps_out, nullptr);
    Motion out = resample_with_prior(m, c.fps_out, out_frames, ctx);
    ASSERT_EQ(out.num_frames(), out_frames);
    EXPECT_EQ(out.fps, c.fps_out);
    EXPECT_TRUE(all_unit_and_finite(out));
    int coinciding = 0;
    for (int i = 0; i < out_frames; ++i) {
      const double src = i * c.fps_in / c.fps_out;
      if (std::abs(src - std::round(src)) > 1e-9) continue;
      const int k = static_cast<int>(std::round(src));
      ++coinciding;
      EXPECT_LT((out.root_positions[i] - m.root_positions[k]).norm(), 1e-6);
      for (int j = 0; j < s.num_joints(); ++j) EXPECT_LT(geodesic_angle(out.rotation(i, j), m.rotation(k, j)), 1e-6);
    }
    EXPECT_GE(coinciding, 2);
  }
}

TEST(PriorCodec, ResidualMakesTheReconstructionExactAtInputFrames) {
  // Without the copy of coinciding frames, the residual alone reproduces the
  // input: check through times that sit 1e-4 frames off the input frames.
  auto model = std::make_shared<const NemfModel>(test::tiny_prior());
  TaskContext ctx = test::context_of(*model);
  Motion m = test::random_motion(model->rig().skeleton, 30, 30.0, 4);
  PriorResampleOptions no_residual;
  no_residual.residual = false;
  Motion plain = resample_with_prior(m, 30.0, 30, ctx, no_residual);
  Motion fixed = resample_with_prior(m, 30.0 * (1 + 1e-4), 30, ctx);
  double plain_err = 0.0, fixed_err = 0.0;
  for (int f = 0; f < 30; ++f) {
    for (int j = 0; j < m.num_joints(); ++j) {
      plain_err = std::max(plain_err, geodesic_angle(plain.rotation(f, j), m.rotation(f, j)));
      fixed_err = std::max(fixed_err, geodesic_angle(fixed.rotation(f, j), m.rotation(f, j)));
    }
  }
  EXPECT_GT(plain_err, 0.05);  // an untrained prior reconstructs badly
  EXPECT_LT(fixed_err, 0.01);  // times ~3e-3 frames off, residual interpolated
}

// Method "prior" at ratios that are not whole: dense input takes the quintic
// (the codec lost to the spline at every input up to 6 times sparser than the model's
// rate), very sparse input the codec with its residual.
TEST(PriorCodec, PriorResamplingTakesTheQuinticOrTheCodecByTheRatio) {
  auto model = std::make_shared<const NemfModel>(test::tiny_prior());
  ASSERT_DOUBLE_EQ(model->config().fps, 30.0);
  TaskContext ctx = test::context_of(*model);
  const std::pair<double, double> dense[] = {{24.0, 30.0}, {30.0, 60.0}, {30.0, 24.0}, {25.0, 120.0}};
  for (const auto& [in_fps, out_fps] : dense) {
    const Motion m = test::random_motion(model->rig().skeleton, 25, in_fps, 3);
    const Motion prior = run_resample(m, out_fps, "prior", nullptr, ctx);
    const Motion quintic = run_resample(m, out_fps, "quintic", nullptr, ctx);
    ASSERT_EQ(prior.num_frames(), quintic.num_frames()) << in_fps << " -> " << out_fps;
    for (int f = 0; f < prior.num_frames(); ++f) {
      EXPECT_TRUE(prior.root_positions[f] == quintic.root_positions[f]) << f;
      for (int j = 0; j < prior.num_joints(); ++j) EXPECT_TRUE(prior.rotation(f, j).coeffs() == quintic.rotation(f, j).coeffs());
    }
  }
  // 4 fps -> 30 (7.5 times sparser): the codec, through every input frame.
  const Motion m = test::random_motion(model->rig().skeleton, 9, 4.0, 4);
  const Motion prior = run_resample(m, 30.0, "prior", nullptr, ctx);
  const Motion quintic = run_resample(m, 30.0, "quintic", nullptr, ctx);
  ASSERT_EQ(prior.num_frames(), 61);
  double differs = 0.0;
  for (int f = 0; f < prior.num_frames(); ++f) {
    for (int j = 0; j < prior.num_joints(); ++j)
      differs = std::max(differs, geodesic_angle(prior.rotation(f, j), quintic.rotation(f, j)));
  }
  EXPECT_GT(differs, 1e-3);
  for (int k = 0; k < m.num_frames(); k += 2) {  // input frame k is output frame 7.5 k
    for (int j = 0; j < m.num_joints(); ++j)
      EXPECT_LT(geodesic_angle(prior.rotation(15 * k / 2, j), m.rotation(k, j)), 1e-5) << k << " " << j;
  }
}

// Method "prior" at a whole ratio (7.5 -> 30 fps: the quintic blended with a
// latent solve): where the solve cannot fit the input frames (an untrained
// prior here) the quintic is kept and a warning says why; without the
// fallback the solve's blend is returned.
TEST(PriorCodec, PriorResamplingKeepsTheQuinticWhereTheSolveMissesTheInput) {
  auto model = std::make_shared<const NemfModel>(test::tiny_prior());
  TaskContext ctx = test::context_of(*model);
  const Motion m = test::random_motion(model->rig().skeleton, 9, 7.5, 5);
  std::vector<std::string> warnings;
  const Motion kept = run_resample(m, 30.0, "prior", &warnings, ctx);
  const Motion quintic = run_resample(m, 30.0, "quintic", nullptr, ctx);
  ASSERT_EQ(kept.num_frames(), quintic.num_frames());
  double kept_diff = 0.0;
  for (int f = 0; f < kept.num_frames(); ++f) {
    for (int j = 0; j < kept.num_joints(); ++j)
      kept_diff = std::max(kept_diff, geodesic_angle(kept.rotation(f, j), quintic.rotation(f, j)));
  }
  EXPECT_LT(kept_diff, 1e-5);
  ASSERT_FALSE(warnings.empty());
  EXPECT_NE(warnings.back().find("the prior could not reach the keys"), std::string::npos) << warnings.back();
  ctx.interpolation_fallback = false;
  const Motion solved = run_resample(m, 30.0, "prior", nullptr, ctx);
  double solved_diff = 0.0;
  for (int f = 0; f < solved.num_frames(); ++f) {
    for (int j = 0; j < solved.num_joints(); ++j)
      solved_diff = std::max(solved_diff, geodesic_angle(solved.rotation(f, j), quintic.rotation(f, j)));
  }
  EXPECT_GT(solved_diff, 1e-3);
}

TEST(PriorCodec, RejectsBadInput) {
  auto model = std::make_shared<const NemfModel>(test::tiny_prior());
  TaskContext none;
  Motion m = test::random_motion(model->rig().skeleton, 10, 30.0, 2);
  EXPECT_THROW(resample_with_prior(m, 60.0, 19, none), InputError);
  TaskContext ctx = test::context_of(*model);
  EXPECT_THROW(resample_with_prior(m, -1.0, 19, ctx), InputError);
  const runtime::NemfRuntime& rt = *ctx.model;
  EXPECT_THROW(encode_motion(rt, m.slice(0, 1)), InputError);
  Motion other = m;
  other.skeleton.names[1] = "Other";
  EXPECT_THROW(encode_motion(rt, other), InputError);
  EncodedMotion code = encode_motion(rt, m);
  code.windows[0].z_l = Eigen::VectorXf::Zero(3);
  EXPECT_THROW(decode_motion(rt, code, 30.0, 10), InputError);
  EXPECT_THROW(resample_with_prior(m, 60.0, 19, none), ModelMissingError);
  // Through the task entry point: "prior" needs a model.
  EXPECT_THROW(run_resample(m, 60.0, "prior", nullptr, none), InputError);
  EXPECT_EQ(run_resample(m, 60.0, "prior", nullptr, ctx).num_frames(), 19);
}

}  // namespace
}  // namespace mf
