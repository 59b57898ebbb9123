#include "tests/runtime_test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "prior/motion/motion_bvh.h"
#include "tasks/context/model_rig.h"
#include "tasks/context/task_context.h"

namespace mf::test {

const std::string& shipped_model_path() {
  static const std::string path = std::string(MF_SOURCE_DIR) + "/models/motionfield-prior.mfm";
  return path;
}

const BothModels& shipped_models() {
  static const BothModels m;
  return m;
}

const NemfModel& float64_model() {
  static const NemfModel m = [] {
    NemfModel model = load_nemf(shipped_model_path());
    at::NoGradGuard no_grad;
    for (auto& named : model.named_parameters()) named.second.set_data(named.second.to(at::kDouble));
    NemfStats& s = model.stats();
    for (at::Tensor* t : {&s.feature_mean, &s.feature_std, &s.root_mean, &s.root_std, &s.gmp_in_mean, &s.gmp_in_std,
                          &s.gmp_out_mean, &s.gmp_out_std})
      *t = t->to(at::kDouble);
    return model;
  }();
  return m;
}

at::Tensor to_tensor(const Eigen::Ref<const MatrixRXf>& m) {
  const MatrixRXf copy = m;
  return at::from_blob(const_cast<float*>(copy.data()), {copy.rows(), copy.cols()}, at::kFloat).clone();
}

MatrixRXf to_matrix(const at::Tensor& t) {
  const at::Tensor c = t.detach().to(at::kFloat).contiguous().reshape({t.size(0), -1});
  return Eigen::Map<const MatrixRXf>(c.data_ptr<float>(), c.size(0), c.size(1));
}

Eigen::VectorXf to_vector(const at::Tensor& t) {
  const at::Tensor c = t.detach().to(at::kFloat).contiguous().reshape({-1});
  return Eigen::Map<const Eigen::VectorXf>(c.data_ptr<float>(), c.numel());
}

double relative_difference(const Eigen::Ref<const MatrixRXf>& a, const Eigen::Ref<const MatrixRXf>& b) {
  EXPECT_EQ(a.rows(), b.rows());
  EXPECT_EQ(a.cols(), b.cols());
  if (a.rows() != b.rows() || a.cols() != b.cols()) return 1.0;
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

double relative_vector_difference(const Eigen::VectorXf& a, const Eigen::VectorXf& b) {
  return relative_difference(MatrixRXf(a.transpose()), MatrixRXf(b.transpose()));
}

MatrixRXf normal_matrix(Eigen::Index rows, Eigen::Index cols, std::mt19937& rng) {
  std::normal_distribution<float> n;
  MatrixRXf m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = n(rng);
  return m;
}

std::vector<double> term_differences(const RuntimeEnergyTerms& runtime, const EnergyTerms& torch,
                                     const std::string& what) {
  EXPECT_EQ(runtime.terms.size(), torch.terms.size()) << what;
  std::vector<double> d;
  for (size_t i = 0; i < std::min(runtime.terms.size(), torch.terms.size()); ++i) {
    EXPECT_EQ(runtime.terms[i].first, torch.terms[i].first) << what;
    const double ref = torch.terms[i].second.item<double>();
    d.push_back(std::abs(runtime.terms[i].second - ref) / std::abs(ref));
  }
  return d;
}

double code_gradient_difference(const Eigen::VectorXf& g_zl, const Eigen::VectorXf& g_zg, const at::Tensor& t_zl,
                                const at::Tensor& t_zg) {
  Eigen::VectorXf grad(g_zl.size() + g_zg.size()), ref(grad.size());
  grad << g_zl, g_zg;
  ref << to_vector(t_zl.grad()), to_vector(t_zg.grad());
  return relative_vector_difference(grad, ref);
}

void expect_total_and_gradient(const RuntimeEnergyTerms& runtime, const EnergyTerms& torch,
                               const Eigen::VectorXf& g_zl, const Eigen::VectorXf& g_zg, const at::Tensor& t_zl,
                               const at::Tensor& t_zg, const std::string& what, Agreement* a) {
  const double total = std::abs(runtime.total - torch.total.item<double>()) / std::abs(torch.total.item<double>());
  EXPECT_LT(total, kOutputTolerance) << what;
  a->value = std::max(a->value, total);
  a->gradient = code_gradient_difference(g_zl, g_zg, t_zl, t_zg);
  EXPECT_LT(a->gradient, kGradientTolerance) << what;
}

TaskContext shipped_context(bool libtorch) {
  const BothModels& m = shipped_models();
  TaskContext ctx;
  ctx.model = std::shared_ptr<const runtime::NemfRuntime>(std::shared_ptr<const void>(), &m.runtime);
  if (libtorch) ctx.reference = libtorch_energies(std::shared_ptr<const NemfModel>(std::shared_ptr<const void>(), &m.frozen));
  return ctx;
}

const Motion& walk_on_model_rig() {
  static const Motion m = [] {
    const Motion walk = read_motion(std::string(MF_SOURCE_DIR) + "/samples/walk_keyframes.bvh");
    TaskContext ctx;
    ctx.model = std::make_shared<const runtime::NemfRuntime>(runtime::NemfRuntime::load(shipped_model_path()));
    ctx.model_anatomy = load_rig_anatomy_next_to(shipped_model_path(), ctx.model->rig().skeleton);
    return model_retargeter(walk, {}, ctx).to_model(walk);
  }();
  return m;
}

runtime::NemfRuntime runtime_of(const NemfModel& model) {
  const std::vector<uint8_t> bytes = serialize_nemf(model);
  return runtime::NemfRuntime::from_bytes(bytes.data(), bytes.size(), "test prior");
}

TaskContext context_of(const NemfModel& model) {
  TaskContext ctx;
  ctx.model = std::make_shared<const runtime::NemfRuntime>(runtime_of(model));
  return ctx;
}

std::shared_ptr<const runtime::NemfRuntime> shared_runtime_of(const NemfModel& model) {
  return std::make_shared<const runtime::NemfRuntime>(runtime_of(model));
}

std::shared_ptr<const runtime::InbetweenerRuntime> runtime_of(const InbetweenModel& model) {
  const std::vector<uint8_t> bytes = serialize_inbetweener(model);
  return runtime::inbetweener_runtime_from_bytes(bytes.data(), bytes.size(), "test " + model.kind());
}

}  // namespace mf::test
