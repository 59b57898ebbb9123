#include "bench/motion_features.h"

#include <ATen/ATen.h>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cstdio>
#include <numeric>
#include <random>
#include <sstream>

#include "prior/model/model_file.h"
#include "prior/model/representation.h"
#include "prior/motion/errors.h"
#include "tasks/context/task_context.h"

namespace mf::bench {

MotionFeatures::MotionFeatures(const std::string& model_path) : model_(load_nemf(model_path)) {}

int MotionFeatures::window() const { return model_.config().window; }

Eigen::VectorXd MotionFeatures::features(const Motion& window) const {
  check_model_skeleton(model_.rig(), window.skeleton, "window");
  const int T = window.num_frames();
  if (T < 2 || T > model_.config().window)
    throw InputError("a feature window needs 2 to " + std::to_string(model_.config().window) + " frames, not " +
                     std::to_string(T));
  at::NoGradGuard no_grad;
  const at::Tensor rotations = window_tensors(window, 0, T, model_.rig(), 0).local_rotations;
  const NemfLatent z = model_.encode(rotations, at::ones({1, T}, at::kFloat));
  const at::Tensor mu = at::cat({z.mu_l.reshape({-1}), z.mu_g.reshape({-1})}).to(at::kDouble).contiguous();
  return Eigen::Map<const Eigen::VectorXd>(mu.data_ptr<double>(), mu.numel());
}

Eigen::MatrixXd stack_rows(const std::vector<Eigen::VectorXd>& rows) {
  Eigen::MatrixXd m(static_cast<Eigen::Index>(rows.size()), rows.empty() ? 0 : rows.front().size());
  for (size_t i = 0; i < rows.size(); ++i) m.row(static_cast<Eigen::Index>(i)) = rows[i].transpose();
  return m;
}

namespace {

// The symmetric square root of a symmetric positive semi-definite matrix.
Eigen::MatrixXd psd_sqrt(const Eigen::MatrixXd& c) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(c);
  const Eigen::VectorXd roots = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return eig.eigenvectors() * roots.asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace

double frechet_distance(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  if (a.rows() < 2 || b.rows() < 2 || a.cols() != b.cols())
    throw InputError("the Frechet distance needs two sets of at least two feature rows of one size");
  const Eigen::RowVectorXd mu_a = a.colwise().mean(), mu_b = b.colwise().mean();
  const Eigen::MatrixXd da = a.rowwise() - mu_a, db = b.rowwise() - mu_b;
  const Eigen::MatrixXd ca = da.transpose() * da / static_cast<double>(a.rows() - 1);
  const Eigen::MatrixXd cb = db.transpose() * db / static_cast<double>(b.rows() - 1);
  const Eigen::MatrixXd root_a = psd_sqrt(ca);
  const Eigen::MatrixXd middle = root_a * cb * root_a;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (middle + middle.transpose()), Eigen::EigenvaluesOnly);
  const double trace_root = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt().sum();
  // Identical sets can round a hair below zero.
  return std::max(0.0, (mu_a - mu_b).squaredNorm() + ca.trace() + cb.trace() - 2.0 * trace_root);
}

double feature_diversity(const Eigen::MatrixXd& features, uint64_t seed) {
  const Eigen::Index n = features.rows();
  if (n < 2) throw InputError("diversity needs at least two feature rows");
  std::vector<Eigen::Index> order(static_cast<size_t>(n));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  std::mt19937_64 rng(seed);
  std::shuffle(order.begin(), order.end(), rng);
  const Eigen::Index half = n / 2;
  double sum = 0.0;
  for (Eigen::Index i = 0; i < half; ++i) sum += (features.row(order[i]) - features.row(order[half + i])).norm();
  return sum / static_cast<double>(half);
}

FeatureSets::Set& FeatureSets::at(const std::string& set) {
  auto [it, inserted] = sets_.try_emplace(set);
  if (inserted) order_.push_back(set);
  return it->second;
}

void FeatureSets::add(const std::string& set, const Eigen::VectorXd& truth, const Eigen::VectorXd& generated) {
  Set& s = at(set);
  s.truth.push_back(truth);
  s.generated.push_back(generated);
}

void FeatureSets::add_truth(const std::string& set, const Eigen::VectorXd& truth) { at(set).truth.push_back(truth); }

void FeatureSets::add_generated(const std::string& set, const Eigen::VectorXd& generated) {
  at(set).generated.push_back(generated);
}

std::string FeatureSets::table() const {
  std::ostringstream s;
  s << "| set | windows | FID to the real windows | diversity | diversity of the real windows |\n"
    << "|---|---:|---:|---:|---:|\n";
  char line[256];
  for (const std::string& name : order_) {
    const Set& set = sets_.at(name);
    const std::string windows = set.truth.size() == set.generated.size()
                                    ? std::to_string(set.truth.size())
                                    : std::to_string(set.generated.size()) + " / " + std::to_string(set.truth.size());
    if (set.truth.size() < 2 || set.generated.size() < 2) {
      std::snprintf(line, sizeof line, "| %s | %s | - | - | - |\n", name.c_str(), windows.c_str());
    } else {
      const Eigen::MatrixXd truth = stack_rows(set.truth), generated = stack_rows(set.generated);
      std::snprintf(line, sizeof line, "| %s | %s | %.4f | %.3f | %.3f |\n", name.c_str(), windows.c_str(),
                    frechet_distance(generated, truth), feature_diversity(generated), feature_diversity(truth));
    }
    s << line;
  }
  return s.str();
}

}  // namespace mf::bench
