// Re-navigation's energy on the Eigen runtime (prior/runtime/), without
// libtorch, with its gradient with respect to the latent codes written out:
// every term of evaluate_renav_energy() / renav_motion_energy()
// (tasks/renav/renav.h: path, joints, heading, foot_skating, continuity), in
// its order, with its weights and means. The decode, the steering GMP on it
// and the root path from the origin are RuntimeDecodePass's
// (tasks/latent/runtime_decode.h); the soft-DTW divergences are
// tasks/renav/soft_dtw_kernels.h's, in double as libtorch's. As there, the
// foot contact probabilities are constants of foot_skating's gradient.
// The heading-frame joint positions are the GMP's inputs (H^T of FK from the
// origin), equal to heading_relative_positions() up to float rounding.
// tests/runtime_renav_equivalence_test.cc holds it to the libtorch energy
// (values within 1e-5, gradients within 1e-4, relative); renavigate()
// minimises it as a RuntimeLatentEnergy (tasks/latent/runtime_latent_energy.h).
#pragma once

#include <Eigen/Core>

#include "prior/runtime/nemf_runtime.h"
#include "tasks/latent/runtime_decode.h"
#include "tasks/latent/runtime_energy.h"
#include "tasks/renav/renav_window.h"

namespace mf {

/// The energy of one window's codes, with the buffers of its evaluations.
/// One per thread; the model and the window must outlive it.
class RenavRuntimeEnergy : private RuntimeDecodePass {
 public:
  /// Throws InputError when the window does not fit the model.
  RenavRuntimeEnergy(const runtime::NemfRuntime& model, const RenavWindow& window, const RenavWeights& weights);

  /// The energy of (z_l [zl], z_g [zg]) and, when g_zl and g_zg are not
  /// null, its gradient with respect to them (resized). Terms named as
  /// RenavEnergy's, weighted.
  RuntimeEnergyTerms evaluate(const Eigen::Ref<const Eigen::VectorXf>& z_l,
                              const Eigen::Ref<const Eigen::VectorXf>& z_g, Eigen::VectorXf* g_zl,
                              Eigen::VectorXf* g_zg);

  /// The decoded window at (z_l, z_g), canonical: local rotations
  /// [T, J * 9], root positions [T, 3] (the GMP's path) and foot contact
  /// probabilities [T, F].
  void decode_window(const Eigen::Ref<const Eigen::VectorXf>& z_l, const Eigen::Ref<const Eigen::VectorXf>& z_g,
                     runtime::MatrixRXf* rotations, runtime::MatrixRXf* root, runtime::MatrixRXf* contacts);

 private:
  void run(const Eigen::Ref<const Eigen::VectorXf>& z_l, const Eigen::Ref<const Eigen::VectorXf>& z_g);
  void add_path(RuntimeEnergyTerms* out);
  void add_joints(RuntimeEnergyTerms* out);
  void add_heading(RuntimeEnergyTerms* out);
  void add_foot_skating(RuntimeEnergyTerms* out);
  void add_continuity(RuntimeEnergyTerms* out);

  const RenavWindow* window_;
  RenavWeights weights_;
  Eigen::VectorXd frames_;
  // The reference's sequences in double and their soft-DTW self values.
  sdtw::RowMatrixXd reference_joints_, reference_heading_;
  double self_joints_ = 0.0, self_heading_ = 0.0;
  sdtw::RowMatrixXd x_, g_x_;  // a sequence of the decode and its gradient
  runtime::MatrixRXf out_positions_, g_out_positions_;
};

}  // namespace mf
