#include "tasks/latent/runtime_decode.h"

#include <cmath>

#include "prior/motion/rotation_kernels.h"
#include "prior/runtime/root_path.h"
#include "prior/runtime/rotations.h"

namespace mf {
namespace {

using runtime::MatrixRXf;
using Matrix3 = Eigen::Matrix<float, 3, 3, Eigen::RowMajor>;
using Map3 = Eigen::Map<Matrix3>;
using ConstMap3 = Eigen::Map<const Matrix3>;
using Row3 = Eigen::Matrix<float, 1, 3>;

}  // namespace

RuntimeDecodePass::RuntimeDecodePass(const runtime::NemfRuntime& model)
    : model_(&model), kinematics_(model.rig().skeleton), root_forward_(model.rig().root_forward.cast<float>()) {}

void RuntimeDecodePass::decode(const Eigen::VectorXd& frames, const Eigen::Ref<const Eigen::VectorXf>& z_l,
                               const Eigen::Ref<const Eigen::VectorXf>& z_g, bool fk) {
  const int S = static_cast<int>(frames.size()), J = kinematics_.joints();
  model_->decode(frames, z_l, z_g, &decoder_ws_, &sixd_);
  runtime::sixd_to_matrix(sixd_, &rotations_);
  if (fk) {
    zero_root_.setZero(S, 3);
    kinematics_.forward(rotations_, zero_root_, &positions_, &globals_);
  }
  if (gradient_) {
    g_rotations_.setZero(S, J * 9);
    g_positions_.setZero(S, J * 3);
  }
}

void RuntimeDecodePass::predict(GmpUse use, int anchor) {
  gmp_inputs();
  model_->predict_global(gmp_in_, use, &gmp_ws_, &gmp_out_);
  root_path(anchor);
  if (gradient_) {
    g_path_.setZero(path_.rows(), 3);
    g_gmp_in_direct_.setZero(gmp_in_.rows(), gmp_in_.cols());
  }
}

void RuntimeDecodePass::predict_vjp(GmpUse use, int anchor) {
  root_path_vjp(anchor);
  model_->predict_global_vjp(&gmp_ws_, use, g_gmp_out_, &g_gmp_in_);
  g_gmp_in_ += g_gmp_in_direct_;
  gmp_inputs_vjp();
}

// gmp_inputs() of representation.h from the dense decode (prior/runtime/root_path.h).
void RuntimeDecodePass::gmp_inputs() { runtime::gmp_inputs(rotations_, positions_, root_forward_, &headings_, &gmp_in_); }

// NemfModel::root_positions() (prior/runtime/root_path.h), then the ground
// position at the anchor moved to the origin.
void RuntimeDecodePass::root_path(int anchor) {
  runtime::integrate_root_path(headings_, gmp_out_, model_->config().fps, &path_);
  const float ax = path_(anchor, 0), az = path_(anchor, 2);
  path_.col(0).array() -= ax;
  path_.col(2).array() -= az;
}

// The gradient of root_path(): from g_path_ to the GMP's outputs (g_gmp_out_)
// and the headings (g_headings_, started here).
void RuntimeDecodePass::root_path_vjp(int anchor) {
  const int T = static_cast<int>(gmp_out_.rows());
  const float fps = static_cast<float>(model_->config().fps);
  g_gmp_out_.setZero(T, gmp_out_.cols());
  g_headings_.setZero(T, 9);
  g_path_(anchor, 0) -= g_path_.col(0).sum();
  g_path_(anchor, 2) -= g_path_.col(2).sum();
  float later_x = 0, later_z = 0;  // the ground gradient of the frames after t: frame t's step feeds them
  for (int t = T - 1; t >= 0; --t) {
    const Eigen::Vector3f g_world(later_x / fps, 0.0f, later_z / fps);
    const ConstMap3 h(&headings_(t, 0));
    g_gmp_out_.row(t).head<3>() = (h.transpose() * g_world).transpose();
    Map3(&g_headings_(t, 0)) += g_world * gmp_out_.row(t).head<3>();
    g_gmp_out_(t, 3) = g_path_(t, 1);
    later_x += g_path_(t, 0);
    later_z += g_path_(t, 2);
  }
}

// The gradient of gmp_inputs(): from g_gmp_in_ (and the headings' gradient)
// to the decoded rotations and positions.
void RuntimeDecodePass::gmp_inputs_vjp() {
  const int T = static_cast<int>(rotations_.rows()), J = kinematics_.joints();
  for (int t = 0; t < T; ++t) {
    const ConstMap3 h(&headings_(t, 0)), root(&rotations_(t, 0));
    Map3 g_h(&g_headings_(t, 0)), g_root(&g_rotations_(t, 0));
    for (int j = 0; j < J; ++j) {
      const Eigen::Vector3f g = g_gmp_in_.row(t).segment<3>(j * 3).transpose();
      g_positions_.row(t).segment<3>(j * 3) += (h * g).transpose();
      g_h += positions_.row(t).segment<3>(j * 3).transpose() * g.transpose();
    }
    Matrix3 g_free = Matrix3::Zero();
    g_free.col(0) = g_gmp_in_.row(t).segment<3>(J * 3).transpose();
    g_free.col(1) = g_gmp_in_.row(t).segment<3>(J * 3 + 3).transpose();
    g_root += h * g_free;
    g_h += root * g_free.transpose();
    Matrix3 g_from_heading;
    kernels::heading_rotation_vjp(&rotations_(t, 0), root_forward_.data(), &g_headings_(t, 0), g_from_heading.data());
    g_root += g_from_heading;
  }
}

void RuntimeDecodePass::backward(bool fk, Eigen::VectorXf* g_zl, Eigen::VectorXf* g_zg) {
  if (fk) {
    kinematics_.vjp(rotations_, globals_, g_positions_, nullptr, &g_local_, &g_root_);
    g_rotations_ += g_local_;
  }
  runtime::sixd_to_matrix_vjp(sixd_, g_rotations_, &g_sixd_);
  model_->decode_vjp(&decoder_ws_, g_sixd_, g_zl, g_zg);
}

double RuntimeDecodePass::foot_skating(const MatrixRXf& positions, double weight, MatrixRXf* g_positions) const {
  const RigInfo& rig = model_->rig();
  const int T = static_cast<int>(positions.rows()), F = rig.num_feet();
  const float fps = static_cast<float>(model_->config().fps);
  const double n = static_cast<double>(T - 1) * F;
  double sum = 0;
  for (int t = 0; t + 1 < T; ++t) {
    for (int i = 0; i < F; ++i) {
      const int j = rig.foot_joints[i];
      const Row3 v = (positions.row(t + 1).segment<3>(j * 3) - positions.row(t).segment<3>(j * 3)) * fps;
      const float contact = 1.0f / (1.0f + std::exp(-gmp_out_(t + 1, 4 + i)));
      sum += contact * (v.x() * v.x() + v.z() * v.z());
      if (!gradient_) continue;
      const float g = static_cast<float>(weight / n * contact * 2 * fps);
      const Row3 g_v(g * v.x(), 0.0f, g * v.z());
      g_positions->row(t + 1).segment<3>(j * 3) += g_v;
      g_positions->row(t).segment<3>(j * 3) -= g_v;
    }
  }
  return sum / n;
}

}  // namespace mf
