#include "tasks/renav/renav_runtime_energy.h"

#include <cmath>
#include <string>

#include "prior/motion/errors.h"
#include "prior/motion/rotation_kernels.h"

namespace mf {
namespace {

using runtime::MatrixRXf;
using Row3 = Eigen::Matrix<float, 1, 3>;

// Throws unless `window` fits a model of J joints and windows of `W` frames.
void check_window(const RenavWindow& w, int J, int W) {
  const int T = w.length, S = w.num_shared();
  if (T < 2 || T > W) throw InputError("re-navigation energy: a window of 2 to " + std::to_string(W) + " frames");
  if (w.target_xz.rows() != T || w.target_xz.cols() != 2 || w.target_tangent.rows() != T ||
      w.target_tangent.cols() != 2)
    throw InputError("re-navigation energy: the target path does not match the window");
  if (w.reference_joints.rows() < 1 || w.reference_joints.cols() != J * 3 ||
      w.reference_heading.rows() != w.reference_joints.rows() || w.reference_heading.cols() != 1)
    throw InputError("re-navigation energy: the reference's signals do not match the model's rig");
  if (S > T || w.shared_joints.rows() != S ||
      (S > 0 && (w.shared_rotations.cols() != J * 9 || w.shared_joints.cols() != J * 3)))
    throw InputError("re-navigation energy: the shared frames do not match the window");
}

}  // namespace

RenavRuntimeEnergy::RenavRuntimeEnergy(const runtime::NemfRuntime& model, const RenavWindow& window,
                                       const RenavWeights& weights)
    : RuntimeDecodePass(model), window_(&window), weights_(weights) {
  check_window(window, kinematics_.joints(), model.config().window);
  frames_ = Eigen::VectorXd::LinSpaced(window.length, 0.0, window.length - 1.0);
  reference_joints_ = window.reference_joints.cast<double>();
  reference_heading_ = window.reference_heading.cast<double>();
  if (weights.joints > 0) self_joints_ = sdtw::self_value(reference_joints_, weights.gamma);
  if (weights.heading > 0) self_heading_ = sdtw::self_value(reference_heading_, weights.gamma);
}

// The decode at the window's frames, its FK, the steering GMP and the root path from the origin.
void RenavRuntimeEnergy::run(const Eigen::Ref<const Eigen::VectorXf>& z_l,
                             const Eigen::Ref<const Eigen::VectorXf>& z_g) {
  const NemfConfig& config = model_->config();
  if (z_l.size() != config.zl || z_g.size() != config.zg)
    throw InputError("re-navigation energy: expected z_l [" + std::to_string(config.zl) + "] and z_g [" +
                     std::to_string(config.zg) + "]");
  decode(frames_, z_l, z_g, true);
  predict(GmpUse::Steering, 0);
}

RuntimeEnergyTerms RenavRuntimeEnergy::evaluate(const Eigen::Ref<const Eigen::VectorXf>& z_l,
                                                const Eigen::Ref<const Eigen::VectorXf>& z_g, Eigen::VectorXf* g_zl,
                                                Eigen::VectorXf* g_zg) {
  gradient_ = g_zl != nullptr && g_zg != nullptr;
  run(z_l, z_g);
  const RenavWeights& w = weights_;
  RuntimeEnergyTerms out;
  if (w.path > 0) add_path(&out);
  if (w.joints > 0) add_joints(&out);
  if (w.heading > 0) add_heading(&out);
  if (w.foot_skating > 0 && model_->rig().num_feet() > 0) add_foot_skating(&out);
  if (w.continuity > 0 && window_->num_shared() > 0) add_continuity(&out);
  for (const auto& t : out.terms) out.total += t.second;
  if (!gradient_) return out;
  predict_vjp(GmpUse::Steering, 0);
  backward(true, g_zl, g_zg);
  return out;
}

// path: the mean smoothed absolute difference of the root's ground position
// and the target's, over frames and the two axes.
void RenavRuntimeEnergy::add_path(RuntimeEnergyTerms* out) {
  const int T = window_->length;
  const float scale = static_cast<float>(weights_.path / (2.0 * T));
  double sum = 0;
  for (int t = 0; t < T; ++t) {
    for (int i = 0; i < 2; ++i) {
      const float d = path_(t, 2 * i) - window_->target_xz(t, i);
      const float s = std::sqrt(d * d + 1e-6f);
      sum += s;
      if (gradient_) g_path_(t, 2 * i) += scale * d / s;
    }
  }
  out->terms.emplace_back("path", weights_.path * sum / (2.0 * T));
}

// joints: the soft-DTW divergence of the heading-frame joint positions (the
// GMP's inputs' first J * 3 columns) against the reference's.
void RenavRuntimeEnergy::add_joints(RuntimeEnergyTerms* out) {
  const int J3 = kinematics_.joints() * 3;
  x_ = gmp_in_.leftCols(J3).cast<double>();
  const double value = sdtw::divergence(x_, reference_joints_, weights_.gamma, gradient_ ? &g_x_ : nullptr,
                                        &self_joints_);
  if (gradient_) g_gmp_in_direct_.leftCols(J3) += (weights_.joints * g_x_).cast<float>();
  out->terms.emplace_back("joints", weights_.joints * value);
}

// heading: the soft-DTW divergence of c(t), the heading (column 2 of the
// heading rotation) against the target's tangent, against the reference's.
void RenavRuntimeEnergy::add_heading(RuntimeEnergyTerms* out) {
  const int T = window_->length;
  const MatrixRXf& tangent = window_->target_tangent;
  x_.resize(T, 1);
  for (int t = 0; t < T; ++t) x_(t, 0) = headings_(t, 2) * tangent(t, 0) + headings_(t, 8) * tangent(t, 1);
  const double value = sdtw::divergence(x_, reference_heading_, weights_.gamma, gradient_ ? &g_x_ : nullptr,
                                        &self_heading_);
  for (int t = 0; t < T && gradient_; ++t) {
    const float g = static_cast<float>(weights_.heading * g_x_(t, 0));
    float g_h[9] = {}, g_root[9];
    g_h[2] = g * tangent(t, 0);
    g_h[8] = g * tangent(t, 1);
    kernels::heading_rotation_vjp(&rotations_(t, 0), root_forward_.data(), g_h, g_root);
    for (int i = 0; i < 9; ++i) g_rotations_(t, i) += g_root[i];
  }
  out->terms.emplace_back("heading", weights_.heading * value);
}

// foot_skating on the decoded joints with the root on its path.
void RenavRuntimeEnergy::add_foot_skating(RuntimeEnergyTerms* out) {
  const int T = window_->length, J = kinematics_.joints();
  out_positions_ = positions_;
  for (int t = 0; t < T; ++t) {
    for (int j = 0; j < J; ++j) out_positions_.row(t).segment<3>(j * 3) += path_.row(t);
  }
  if (gradient_) g_out_positions_.setZero(T, J * 3);
  const double value = foot_skating(out_positions_, weights_.foot_skating, &g_out_positions_);
  for (int t = 0; t < T && gradient_; ++t) {
    g_positions_.row(t) += g_out_positions_.row(t);
    for (int j = 0; j < J; ++j) g_path_.row(t) += g_out_positions_.row(t).segment<3>(j * 3);
  }
  out->terms.emplace_back("foot_skating", weights_.foot_skating * value);
}

// continuity: on the frames shared with the previous window, the mean
// squared geodesic angle of every local rotation plus 10 x the mean squared
// distance of the heading-frame joint positions.
void RenavRuntimeEnergy::add_continuity(RuntimeEnergyTerms* out) {
  const int S = window_->num_shared(), J = kinematics_.joints();
  const double n = static_cast<double>(S) * J;
  const float scale = static_cast<float>(weights_.continuity / n);
  double angles = 0, distances = 0;
  for (int s = 0; s < S; ++s) {
    for (int j = 0; j < J; ++j) {
      const float* decoded = &rotations_(s, j * 9);
      const float* target = &window_->shared_rotations(s, j * 9);
      const float angle = kernels::geodesic_angle(decoded, target);
      const Row3 d = gmp_in_.row(s).segment<3>(j * 3) - window_->shared_joints.row(s).segment<3>(j * 3);
      angles += angle * angle;
      distances += d.squaredNorm();
      if (!gradient_) continue;
      float g[9];
      kernels::geodesic_angle_vjp(decoded, target, scale * 2 * angle, g, static_cast<float*>(nullptr));
      g_rotations_.row(s).segment<9>(j * 9) += Eigen::Map<const Eigen::Matrix<float, 1, 9>>(g);
      g_gmp_in_direct_.row(s).segment<3>(j * 3) += (scale * 20) * d;
    }
  }
  out->terms.emplace_back("continuity", weights_.continuity * (angles / n + 10.0 * distances / n));
}

void RenavRuntimeEnergy::decode_window(const Eigen::Ref<const Eigen::VectorXf>& z_l,
                                       const Eigen::Ref<const Eigen::VectorXf>& z_g, MatrixRXf* rotations,
                                       MatrixRXf* root, MatrixRXf* contacts) {
  gradient_ = false;
  run(z_l, z_g);
  *rotations = rotations_;
  *root = path_;
  const int F = model_->rig().num_feet();
  *contacts = (1.0f + (-gmp_out_.rightCols(F).array()).exp()).inverse().matrix();
}

}  // namespace mf
