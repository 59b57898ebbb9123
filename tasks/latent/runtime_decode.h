// The decode shared by the energies on the Eigen runtime (the latent solvers'
// RuntimeEnergy, tasks/latent/runtime_energy.h, and re-navigation's
// RenavRuntimeEnergy, tasks/renav/renav_runtime_energy.h): the decoder at
// some frames of a window and the joints' positions with the root at the
// origin (FK), and on a dense decode the global motion predictor (GMP) on
// gmp_inputs() of prior/model/representation.h and the root path it
// integrates; each with its vector-Jacobian product, back to the latent codes.
// The energies derive from it, read its buffers and add their terms'
// gradients to the g_* buffers; the buffers are reused between evaluations.
// No libtorch.
#pragma once

#include <Eigen/Core>

#include "prior/runtime/kinematics.h"
#include "prior/runtime/nemf_runtime.h"

namespace mf {

class RuntimeDecodePass {
 protected:
  /// `model` must outlive the pass.
  explicit RuntimeDecodePass(const runtime::NemfRuntime& model);

  /// The decoder at window frames `frames` (sixd_, rotations_ [S, J * 9]) and,
  /// with `fk`, their joint positions with the root at the origin
  /// (positions_ [S, J * 3], globals_). With gradient_, g_rotations_ and
  /// g_positions_ start at zero.
  void decode(const Eigen::VectorXd& frames, const Eigen::Ref<const Eigen::VectorXf>& z_l,
              const Eigen::Ref<const Eigen::VectorXf>& z_g, bool fk);
  /// On a dense decode with FK: the GMP `use` on its inputs (headings_,
  /// gmp_in_ [T, J * 3 + 6], gmp_out_ [T, 4 + F]) and the root path path_
  /// [T, 3], integrated from the origin and then moved so that its ground
  /// position at `anchor` is the origin. With gradient_, g_path_ and
  /// g_gmp_in_direct_ (the terms' own gradient of gmp_in_) start at zero.
  void predict(GmpUse use, int anchor);
  /// The gradient of predict(): from g_path_ and g_gmp_in_direct_ to
  /// g_rotations_ and g_positions_.
  void predict_vjp(GmpUse use, int anchor);
  /// From g_rotations_ and g_positions_ (when decode() ran FK) to the codes.
  void backward(bool fk, Eigen::VectorXf* g_zl, Eigen::VectorXf* g_zg);
  /// foot_skating of energies.cc on joint positions `positions` [T, J * 3]
  /// (root on its path): the feet's horizontal squared speed weighted by the
  /// GMP's contact probability at the later frame (a constant), mean over
  /// frames and feet. With gradient_, adds `weight` times its gradient to
  /// *g_positions.
  double foot_skating(const runtime::MatrixRXf& positions, double weight, runtime::MatrixRXf* g_positions) const;

  const runtime::NemfRuntime* model_;
  runtime::Kinematics kinematics_;
  Eigen::Vector3f root_forward_;
  bool gradient_ = false;  // whether the evaluation in progress accumulates gradients
  runtime::MatrixRXf sixd_, rotations_, positions_, globals_;
  runtime::MatrixRXf headings_, gmp_in_, gmp_out_, path_;
  // Their gradients.
  runtime::MatrixRXf g_rotations_, g_positions_, g_path_, g_gmp_in_direct_;
  runtime::MatrixRXf g_local_, g_root_;

 private:
  void gmp_inputs();
  void root_path(int anchor);
  void root_path_vjp(int anchor);
  void gmp_inputs_vjp();

  runtime::DecoderWorkspace decoder_ws_;
  runtime::GmpWorkspace gmp_ws_;
  runtime::MatrixRXf zero_root_, g_headings_, g_gmp_out_, g_gmp_in_, g_sixd_;
};

}  // namespace mf
