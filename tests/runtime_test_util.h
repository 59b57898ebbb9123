// Helpers of the tests that hold the Eigen runtime (prior/runtime/,
// tasks/latent/runtime_energy.h) to the libtorch implementations: the shipped
// model loaded both ways, conversions between tensors and row-major float
// matrices, the relative difference the equivalence bounds are stated in, and
// the sample walk on the model's rig; tiny test priors on the runtime.
// Linked into mf_tests only.
#pragma once

#include <ATen/ATen.h>

#include <memory>
#include <random>
#include <string>

#include "prior/model/model_file.h"
#include "prior/motion/motion.h"
#include "prior/runtime/nemf_runtime.h"
#include "tasks/context/task_context.h"

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

/// Standard normal entries.
MatrixRXf normal_matrix(Eigen::Index rows, Eigen::Index cols, std::mt19937& rng);

/// The sample walk (samples/walk_keyframes.bvh, 61 frames) on the shipped
/// model's rig, retargeted as the tasks do; loaded once.
const Motion& walk_on_model_rig();

/// `model` (a test's tiny prior) on the Eigen runtime, through its model file's bytes.
runtime::NemfRuntime runtime_of(const NemfModel& model);
/// A context with `model` and its twin on the Eigen runtime (runtime_of()).
TaskContext context_of(std::shared_ptr<const NemfModel> model);

}  // namespace mf::test
