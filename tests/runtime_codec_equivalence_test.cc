// The prior codec (tasks/latent/prior_codec.h) on the Eigen runtime against
// the same codec on the libtorch networks (NemfModel, through CodecPrior),
// both from the shipped model file, on the sample walk (one short window)
// and on smooth random rotations at 24 fps (several blended windows): the
// window codes within 1e-5 (relative to the largest libtorch value), decodes
// within 1e-5 rad and 1e-5 m, resampling with the prior within 1e-4 (rad, m).
// A clip of independent random rotations per frame, far from any motion,
// holds the codes to 1e-5 too, its decodes to 1e-4 rad (see there). One
// thread, as the other equivalence tests.
#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "prior/model/nemf.h"
#include "prior/motion/rotations.h"
#include "prior/util/threads.h"
#include "tasks/context/task_context.h"
#include "tasks/latent/prior_codec.h"
#include "tests/runtime_test_util.h"
#include "tests/test_util.h"

namespace mf {
namespace {

using test::MatrixRXf;

// The codec's networks on libtorch: the reference the runtime is held to.
class TorchCodecPrior final : public CodecPrior {
 public:
  explicit TorchCodecPrior(const NemfModel& model) : model_(model) {}
  const NemfConfig& config() const override { return model_.config(); }
  const RigInfo& rig() const override { return model_.rig(); }

  void encode(const Rows& local_rotations, Eigen::VectorXf* z_l, Eigen::VectorXf* z_g) const override {
    at::NoGradGuard no_grad;
    const int64_t T = local_rotations.rows(), J = rig().num_joints();
    const NemfLatent z = model_.encode(test::to_tensor(local_rotations).reshape({1, T, J, 3, 3}), at::ones({1, T}));
    *z_l = test::to_vector(z.mu_l[0]);
    *z_g = test::to_vector(z.mu_g[0]);
  }

  void decode(const WindowCode& window, const Eigen::VectorXd& positions, Rows* rotations) const override {
    at::NoGradGuard no_grad;
    const at::Tensor frames = at::from_blob(const_cast<double*>(positions.data()), {positions.size()}, at::kDouble);
    *rotations = test::to_matrix(model_.decode(frames.to(at::kFloat), latent(window.z_l), latent(window.z_g))[0]);
  }

  void root_path(const WindowCode& window, Rows* path) const override {
    at::NoGradGuard no_grad;
    const at::Tensor dense =
        model_.decode(at::arange(window.length, at::kFloat), latent(window.z_l), latent(window.z_g));
    *path = test::to_matrix(model_.root_positions(dense, model_.predict_global(dense))[0]);
  }

 private:
  static at::Tensor latent(const Eigen::VectorXf& z) { return test::to_tensor(MatrixRXf(z.transpose())); }
  const NemfModel& model_;
};

const runtime::NemfRuntime& runtime_model() { return test::shipped_models().runtime; }
const TorchCodecPrior& torch_model() {
  static const TorchCodecPrior prior(test::shipped_models().frozen);
  return prior;
}

// The largest differences of two motions of one size: rotations (rad) and root positions (m).
struct MotionDifference {
  double radians = 0.0, metres = 0.0;
};
MotionDifference difference(const Motion& a, const Motion& b) {
  EXPECT_EQ(a.num_frames(), b.num_frames());
  EXPECT_EQ(a.num_joints(), b.num_joints());
  MotionDifference d;
  for (int f = 0; f < std::min(a.num_frames(), b.num_frames()); ++f) {
    d.metres = std::max(d.metres, (a.root_positions[f] - b.root_positions[f]).norm());
    for (int j = 0; j < a.num_joints(); ++j)
      d.radians = std::max(d.radians, geodesic_angle(a.rotation(f, j), b.rotation(f, j)));
  }
  return d;
}

// A clip of independent random local rotations (uniform on the sphere of
// quaternions) and a random root path, at `fps`.
Motion random_rotations(int frames, double fps, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  Motion m = Motion::identity(runtime_model().rig().skeleton, frames, fps);
  for (int f = 0; f < frames; ++f) {
    m.root_positions[f] = Eigen::Vector3d(0.1 * f + 0.05 * normal(rng), 0.9 + 0.05 * normal(rng), 0.05 * normal(rng));
    for (int j = 0; j < m.num_joints(); ++j) {
      const double w = normal(rng), x = normal(rng), y = normal(rng), z = normal(rng);
      m.rotation(f, j) = Eigen::Quaterniond(w, x, y, z).normalized();
    }
  }
  return m;
}

// A clip's codes both ways, the runtime's within 1e-5 of libtorch's; then
// both decoders on the runtime's codes (kPrior) at three frame rates, and
// each side's decode of its own codes: rotations within `radians`, root
// positions within 1e-5 m.
void expect_codecs_agree(const Motion& clip, const char* name, double radians = 1e-5) {
  const EncodedMotion rt = encode_motion(runtime_model(), clip);
  const EncodedMotion th = encode_motion(torch_model(), clip);
  ASSERT_EQ(rt.windows.size(), th.windows.size()) << name;
  double codes = 0.0;
  for (size_t k = 0; k < rt.windows.size(); ++k) {
    codes = std::max({codes, test::relative_vector_difference(rt.windows[k].z_l, th.windows[k].z_l),
                      test::relative_vector_difference(rt.windows[k].z_g, th.windows[k].z_g)});
  }
  EXPECT_LE(codes, test::kOutputTolerance) << name;
  std::printf("%s: %zu windows, codes %.3g relative\n", name, rt.windows.size(), codes);
  for (double fps : {30.0, 60.0, 24.0}) {
    const int frames = static_cast<int>(std::floor(rt.duration() * fps + 1e-6)) + 1;
    const MotionDifference same = difference(decode_motion(runtime_model(), rt, fps, frames),
                                             decode_motion(torch_model(), rt, fps, frames));
    EXPECT_LE(same.radians, radians) << name << " at " << fps << " fps";
    EXPECT_LE(same.metres, 1e-5) << name << " at " << fps << " fps";
    const MotionDifference own = difference(decode_motion(runtime_model(), rt, fps, frames),
                                            decode_motion(torch_model(), th, fps, frames));
    EXPECT_LE(own.radians, radians) << name << " at " << fps << " fps, each its own codes";
    EXPECT_LE(own.metres, 1e-5) << name << " at " << fps << " fps, each its own codes";
    std::printf("%s at %g fps: same codes %.3g rad %.3g m, own codes %.3g rad %.3g m\n", name, fps, same.radians,
                same.metres, own.radians, own.metres);
  }
}

TEST(RuntimeCodecEquivalence, CodesAndDecodesOfTheWalk) {
  ScopedComputeThreads one_thread(1);
  expect_codecs_agree(test::walk_on_model_rig(), "walk");
}

TEST(RuntimeCodecEquivalence, CodesAndDecodesOfSmoothRandomRotations) {
  ScopedComputeThreads one_thread(1);
  expect_codecs_agree(test::random_motion(runtime_model().rig().skeleton, 300, 24.0, 5), "smooth random rotations");
}

// Independent random rotations: decoded root orientations whose 6D first
// column is ~0.1 long against outputs up to ~40 (the decoder agrees to
// ~1e-7 of the largest, tests/runtime_equivalence_test.cc), so
// orthonormalisation turns float rounding into up to ~3e-5 rad, and
// overlapping windows that disagree by up to 3 rad blend them near
// cancellation. The codes still agree within 1e-5.
TEST(RuntimeCodecEquivalence, CodesAndDecodesOfIndependentRandomRotations) {
  ScopedComputeThreads one_thread(1);
  expect_codecs_agree(random_rotations(300, 24.0, 5), "independent random rotations", 1e-4);
}

// resample_with_prior through the context's runtime against the libtorch
// networks: the residual on, the root path from the prior and from the input.
TEST(RuntimeCodecEquivalence, ResamplingWithThePrior) {
  ScopedComputeThreads one_thread(1);
  TaskContext ctx;
  ctx.model = std::shared_ptr<const runtime::NemfRuntime>(std::shared_ptr<const void>(), &runtime_model());
  const Motion& walk = test::walk_on_model_rig();
  for (RootSource root : {RootSource::kPrior, RootSource::kInput}) {
    PriorResampleOptions options;
    options.root = root;
    for (const Motion& clip : {walk, test::random_motion(walk.skeleton, 40, 4.0, 9)}) {
      const int frames = static_cast<int>(std::floor((clip.num_frames() - 1) * 60.0 / clip.fps + 1e-6)) + 1;
      const MotionDifference d = difference(resample_with_prior(clip, 60.0, frames, ctx, options),
                                            resample_with_prior(torch_model(), clip, 60.0, frames, options));
      EXPECT_LE(d.radians, 1e-4) << "root " << static_cast<int>(root) << " from " << clip.fps << " fps";
      EXPECT_LE(d.metres, 1e-4) << "root " << static_cast<int>(root) << " from " << clip.fps << " fps";
      std::printf("resample %g -> 60 fps, root %d: %.3g rad %.3g m\n", clip.fps, static_cast<int>(root), d.radians,
                  d.metres);
    }
  }
}

}  // namespace
}  // namespace mf
