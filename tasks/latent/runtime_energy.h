// The latent solvers' energy on the Eigen runtime (prior/runtime/), without
// libtorch, with its gradient with respect to the latent codes written out:
// every term of evaluate_energy() (tasks/reference/energies.h), in its order,
// under either penalty and with the same rule of which terms are active
// (active_terms(), energy_weights.h). The decode, the GMP on the dense
// decode and its root path (integrated and aligned at the anchor) are
// RuntimeDecodePass's (tasks/latent/runtime_decode.h). runtime_energy.cc: the
// key terms (rotation, root_orientation, position), root_translation and
// latent_prior; runtime_energy_output.cc: the terms on the output motion
// (effector, contact, trajectory, trajectory_facing, foot_skating,
// smoothness), which see the keys' residuals blended in when
// EnergyWeights::on_output asks (tasks/latent/runtime_blend.h). As in
// energies.cc, foot_skating's contact probabilities are constants of its
// gradient.
// Values and gradients match the libtorch energy
// (tests/runtime_energy_test.cc: values within 1e-5, gradients within 1e-4,
// relative; a contact term of small velocities, which float, libtorch's too,
// gives to 2e-5 only, within 1e-5 of the float64 prior's).
//
// This header and its implementation include no libtorch;
// tasks/latent/runtime_latent_energy.h converts the tensor WindowProblem.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "prior/runtime/kinematics.h"
#include "prior/runtime/nemf_runtime.h"
#include "tasks/latent/energy_weights.h"
#include "tasks/latent/runtime_blend.h"
#include "tasks/latent/runtime_decode.h"
#include "tasks/latent/window_problem.h"

namespace mf {

/// An evaluation's weighted terms (named and ordered as evaluate_energy's)
/// and their sum.
struct RuntimeEnergyTerms {
  double total = 0.0;
  std::vector<std::pair<std::string, double>> terms;
};

/// The energy of one model's latent codes, with the buffers of its
/// evaluations (reused: after the first evaluation of a problem's size it
/// allocates little). One per thread; the model must outlive it.
class RuntimeEnergy : private RuntimeDecodePass {
 public:
  explicit RuntimeEnergy(const runtime::NemfRuntime& model);

  /// The energy of (z_l [zl], z_g [zg]) on `problem` under `weights`, and,
  /// when g_zl and g_zg are not null, its gradient with respect to them
  /// (resized). Throws InputError when the problem does not fit the model.
  RuntimeEnergyTerms evaluate(const RuntimeWindowProblem& problem, const EnergyWeights& weights,
                              const Eigen::Ref<const Eigen::VectorXf>& z_l,
                              const Eigen::Ref<const Eigen::VectorXf>& z_g, Eigen::VectorXf* g_zl,
                              Eigen::VectorXf* g_zg);

  /// The solution (z_l, z_g) of `problem`'s window (decode_window() of
  /// energies.h): the whole window decoded, the GMP's root path aligned at
  /// the anchor and its contact probabilities.
  DecodedWindow decode_window(const RuntimeWindowProblem& problem, const Eigen::Ref<const Eigen::VectorXf>& z_l,
                              const Eigen::Ref<const Eigen::VectorXf>& z_g);

 private:
  void decode_rows(const RuntimeWindowProblem& problem, const ActiveTerms& a,
                   const Eigen::Ref<const Eigen::VectorXf>& z_l, const Eigen::Ref<const Eigen::VectorXf>& z_g);
  void add_key_terms(const RuntimeWindowProblem& problem, const EnergyWeights& w, const ActiveTerms& a,
                     RuntimeEnergyTerms* out);
  void add_dense_terms(const RuntimeWindowProblem& problem, const EnergyWeights& w, const ActiveTerms& a,
                       RuntimeEnergyTerms* out);
  void add_root_translation(const RuntimeWindowProblem& problem, const EnergyWeights& w, const ActiveTerms& a,
                            RuntimeEnergyTerms* out);
  void output_motion(const RuntimeWindowProblem& problem, const EnergyWeights& w);
  void add_output_terms(const RuntimeWindowProblem& problem, const EnergyWeights& w, const ActiveTerms& a,
                        RuntimeEnergyTerms* out);
  void add_effector(const RuntimeWindowProblem& problem, const EnergyWeights& w, RuntimeEnergyTerms* out);
  void add_contact(const RuntimeWindowProblem& problem, const EnergyWeights& w, RuntimeEnergyTerms* out);
  void add_trajectory(const RuntimeWindowProblem& problem, const EnergyWeights& w, const ActiveTerms& a,
                      RuntimeEnergyTerms* out);
  void add_foot_skating(const EnergyWeights& w, RuntimeEnergyTerms* out);
  void add_smoothness(const EnergyWeights& w, RuntimeEnergyTerms* out);
  void output_motion_vjp(const RuntimeWindowProblem& problem);

  // The decode's rows: the whole window when a dense term is active, else the key frames.
  Eigen::VectorXd frames_;
  // The output motion of the dense output terms (rotations are rotations_
  // itself when nothing is blended) and its gradients.
  bool blended_ = false;
  RuntimeResidualBlend blend_;
  runtime::MatrixRXf blended_rotations_, out_path_, out_positions_, out_globals_;
  runtime::MatrixRXf g_out_rotations_, g_out_path_, g_out_positions_;
  const runtime::MatrixRXf& out_rotations() const { return blended_ ? blended_rotations_ : rotations_; }
};

}  // namespace mf
