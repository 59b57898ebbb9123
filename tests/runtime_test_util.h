// Helpers of the tests that hold the Eigen runtime (prior/runtime/,
// tasks/latent/runtime_energy.h) to the libtorch implementations: the shipped
// model loaded both ways, conversions between tensors and row-major float
// matrices, the relative difference the equivalence bounds are stated in,
// the sample walk on the model's rig, the check of gradients against
// central differences, and tiny test priors on the runtime. Linked into
// mf_tests only.
#pragma once

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "prior/model/model_file.h"
#include "prior/motion/motion.h"
#include "prior/inbetween/inbetweener.h"
#include "prior/runtime/inbetween_runtime.h"
#include "prior/runtime/nemf_runtime.h"
#include "prior/runtime/tensor_ops.h"
#include "tasks/context/task_context.h"
#include "tasks/reference/latent_energy.h"
#include "tasks/reference/libtorch_energies.h"
#include "tasks/latent/runtime_energy.h"

namespace mf::test {

using runtime::MatrixRXf;

/// Issue 56's bounds, relative to the largest libtorch value compared:
/// outputs within 1e-5, gradients within 1e-4.
constexpr double kOutputTolerance = 1e-5;
constexpr double kGradientTolerance = 1e-4;
/// The step of central differences of the float64 prior: steps of 1e-5 cross
/// almost none of the ReLU kinks, which made float32 differences disagree by
/// 1e-3 to 1e-1 (steps 1e-3 to 1e-1).
constexpr double kDifferenceStep = 1e-5;

/// Who multiplies the runtime's matrices while it lives (set_gemm_backend).
/// The comparisons with libtorch hold the runtime to the BLAS: libtorch's
/// products are OpenBLAS's, so on the same products the runtime agrees with
/// it to rounding everywhere. The encoded codes of the walk's windows lie
/// within rounding of a leaky ReLU's kink: a change of 1e-5 in z_l moves the
/// float64 prior's gradient by 3.4e-4 relative, and the runtime's kernels,
/// which sum in another order, land across it (3e-4 to 4e-3 from float64
/// there, 1e-6 at random codes). RuntimeEnergy.KernelsMatchTheBlasAtRandomCodes
/// checks the kernels.
class ScopedGemmBackend {
 public:
  explicit ScopedGemmBackend(runtime::GemmBackend backend) : before_(runtime::gemm_backend()) {
    runtime::set_gemm_backend(backend);
  }
  ~ScopedGemmBackend() { runtime::set_gemm_backend(before_); }
  ScopedGemmBackend(const ScopedGemmBackend&) = delete;
  ScopedGemmBackend& operator=(const ScopedGemmBackend&) = delete;

 private:
  runtime::GemmBackend before_;
};

/// models/motionfield-prior.mfm of the source tree.
const std::string& shipped_model_path();

/// The shipped prior both ways, loaded once.
struct BothModels {
  NemfModel frozen = load_nemf(shipped_model_path());  ///< as the solvers use it: the hand-written backward nodes
  runtime::NemfRuntime runtime = runtime::NemfRuntime::load(shipped_model_path());
};
const BothModels& shipped_models();

/// The shipped prior in float64 (parameters and statistics converted in
/// place; it runs the module path, the frozen nodes being float32 only), for
/// central differences that resolve derivatives far below float32 rounding.
const NemfModel& float64_model();

at::Tensor to_tensor(const Eigen::Ref<const MatrixRXf>& m);
/// A tensor's values as [size(0), rest] (float).
MatrixRXf to_matrix(const at::Tensor& t);
Eigen::VectorXf to_vector(const at::Tensor& t);

/// max |a - b| / max |b| (sizes must agree: a failure and 1 otherwise).
double relative_difference(const Eigen::Ref<const MatrixRXf>& a, const Eigen::Ref<const MatrixRXf>& b);
double relative_vector_difference(const Eigen::VectorXf& a, const Eigen::VectorXf& b);

/// The relative difference of each of the runtime's terms from libtorch's
/// (names and order must agree: a failure of `what` otherwise).
std::vector<double> term_differences(const RuntimeEnergyTerms& runtime, const EnergyTerms& torch,
                                     const std::string& what);

/// How far a runtime energy is from libtorch's: its values and its gradient.
struct Agreement {
  double value = 0, gradient = 0;
  /// The worse of both, field by field.
  void merge(const Agreement& o) {
    value = std::max(value, o.value);
    gradient = std::max(gradient, o.gradient);
  }
};

/// The totals' relative difference (expected within kOutputTolerance, merged
/// into a->value) and the gradients' (a->gradient, code_gradient_difference(),
/// expected within kGradientTolerance).
void expect_total_and_gradient(const RuntimeEnergyTerms& runtime, const EnergyTerms& torch,
                               const Eigen::VectorXf& g_zl, const Eigen::VectorXf& g_zg, const at::Tensor& t_zl,
                               const at::Tensor& t_zg, const std::string& what, Agreement* a);

/// relative_vector_difference() of a runtime gradient with respect to the
/// codes (g_zl, g_zg) and libtorch's (the .grad() of t_zl, t_zg).
double code_gradient_difference(const Eigen::VectorXf& g_zl, const Eigen::VectorXf& g_zg, const at::Tensor& t_zl,
                                const at::Tensor& t_zg);

/// The shipped prior as a context (not owning it); `libtorch`: with the
/// libtorch reference energies (TaskContext::reference) for the latent solver.
TaskContext shipped_context(bool libtorch = false);

/// Standard normal entries.
MatrixRXf normal_matrix(Eigen::Index rows, Eigen::Index cols, std::mt19937& rng);

/// <g, f(x + h v)> - <g, f(x - h v)> over 2h for a unit v: the directional
/// derivative that `grad`'s dot with v must match, within 1e-4 of |grad|. The
/// networks' (leaky) ReLUs make the energy smooth only piecewise: a kink
/// inside the stencil (one unit switching within h of x) spoils the quotient
/// whatever the gradient, so the quotient at h / 10 is taken too and the
/// closer one counts (h = `step`).
template <class F>
void expect_directional_derivatives(const Eigen::VectorXd& grad, F&& value_at, std::mt19937& rng, const char* what,
                                    double step = kDifferenceStep) {
  std::normal_distribution<double> n;
  for (int d = 0; d < 3; ++d) {
    Eigen::VectorXd v = d == 0 ? grad : Eigen::VectorXd(grad.unaryExpr([&](double) { return n(rng); }));
    v.normalize();
    double numeric = 0;
    for (double h : {step, step / 10}) {
      const double q = (value_at(h * v) - value_at(-h * v)) / (2 * h);
      if (h == step || std::abs(grad.dot(v) - q) < std::abs(grad.dot(v) - numeric)) numeric = q;
    }
    EXPECT_NEAR(grad.dot(v), numeric, 1e-4 * grad.norm()) << what << ", direction " << d;
    std::printf("%s, direction %d: runtime %.6e, differences %.6e, |diff| / |grad| %.2e\n", what, d, grad.dot(v),
                numeric, std::abs(grad.dot(v) - numeric) / grad.norm());
  }
}

/// The sample walk (samples/walk_keyframes.bvh, 61 frames) on the shipped
/// model's rig, retargeted as the tasks do; loaded once.
const Motion& walk_on_model_rig();

/// `model` (a test's tiny prior) on the Eigen runtime, through its model file's bytes.
runtime::NemfRuntime runtime_of(const NemfModel& model);
std::shared_ptr<const runtime::NemfRuntime> shared_runtime_of(const NemfModel& model);
/// A context with `model` on the Eigen runtime (runtime_of()).
TaskContext context_of(const NemfModel& model);
/// An in-betweener (a test's tiny one) on the Eigen runtime, through its model file's bytes.
std::shared_ptr<const runtime::InbetweenerRuntime> runtime_of(const InbetweenModel& model);

}  // namespace mf::test
