// The latent solvers' energy on the Eigen runtime (prior/runtime/), without
// libtorch, with its gradient with respect to the latent codes written out:
// the terms of evaluate_energy() (tasks/latent/energies.h) that the default
// in-betweening and gap-filling solves use, rotation, position,
// root_orientation, root_translation (the GMP on the dense decode, its root
// path integrated and aligned at the anchor) and latent_prior, under either
// penalty. Values and gradients match the libtorch energy
// (tests/runtime_energy_test.cc: values within 1e-5, gradients within 1e-4,
// relative).
//
// Not ported yet: effector, contact, trajectory, trajectory_facing,
// foot_skating and smoothness (and with them the on-output residual blending
// that only those terms see). A problem and weights that make one of them
// active (the rule of evaluate_energy: a positive weight and something to
// measure) are refused with an InputError naming the term; they are never
// silently left out.
//
// This header and its implementation include no libtorch;
// tasks/latent/runtime_problem.h converts the tensor WindowProblem.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "prior/runtime/kinematics.h"
#include "prior/runtime/nemf_runtime.h"
#include "tasks/latent/energy_weights.h"

namespace mf {

/// The constraints of one window in its canonical frame: WindowProblem
/// (energies.h) as Eigen matrices (float, one row per key; J joints).
struct RuntimeWindowProblem {
  int length = 0;                        ///< T, frames of the window
  int anchor = 0;                        ///< window frame of the canonical transform (a key that fixes the root)
  std::vector<int> key_frames;           ///< [K] window frames
  runtime::MatrixRXf key_rotations;      ///< [K, J * 9] targets, row-major 3x3 per joint
  runtime::MatrixRXf key_rotation_mask;  ///< [K, J] 1 where the joint's rotation is constrained
  runtime::MatrixRXf key_positions;      ///< [K, J * 3] root-relative FK positions of the targets
  runtime::MatrixRXf key_position_mask;  ///< [K, J] 1 where the joint and its ancestors are constrained
  runtime::MatrixRXf key_root;           ///< [K, 3] canonical root positions
  Eigen::VectorXf key_root_mask;         ///< [K] 1 where the root position is constrained
  /// The constraints of terms not ported, counted only: an energy whose
  /// weights make one of their terms active refuses the problem.
  int num_effectors = 0, num_pin_steps = 0, num_trajectory = 0;

  int num_keys() const { return static_cast<int>(key_frames.size()); }
};

/// An evaluation's weighted terms (named and ordered as evaluate_energy's)
/// and their sum.
struct RuntimeEnergyTerms {
  double total = 0.0;
  std::vector<std::pair<std::string, double>> terms;
};

/// The energy of one model's latent codes, with the buffers of its
/// evaluations (reused: after the first evaluation of a problem's size it
/// allocates little). One per thread; the model must outlive it.
class RuntimeEnergy {
 public:
  explicit RuntimeEnergy(const runtime::NemfRuntime& model);

  /// The energy of (z_l [zl], z_g [zg]) on `problem` under `weights`, and,
  /// when g_zl and g_zg are not null, its gradient with respect to them
  /// (resized). Throws InputError when an active term is not ported (see the
  /// top of this file) or the problem does not fit the model.
  RuntimeEnergyTerms evaluate(const RuntimeWindowProblem& problem, const EnergyWeights& weights,
                              const Eigen::Ref<const Eigen::VectorXf>& z_l,
                              const Eigen::Ref<const Eigen::VectorXf>& z_g, Eigen::VectorXf* g_zl,
                              Eigen::VectorXf* g_zg);

  /// Whether every term that `weights` make active on `problem` (the rule
  /// above) is ported, i.e. evaluate() does not refuse them.
  bool ports(const RuntimeWindowProblem& problem, const EnergyWeights& weights) const;

 private:
  void decode(const RuntimeWindowProblem& problem, const ActiveTerms& a, const Eigen::Ref<const Eigen::VectorXf>& z_l,
              const Eigen::Ref<const Eigen::VectorXf>& z_g);
  void add_key_terms(const RuntimeWindowProblem& problem, const EnergyWeights& w, const ActiveTerms& a,
                     RuntimeEnergyTerms* out);
  void add_root_translation(const RuntimeWindowProblem& problem, const EnergyWeights& w, const ActiveTerms& a,
                            RuntimeEnergyTerms* out);
  void gmp_inputs();
  void root_path(int anchor);
  void root_path_vjp(int anchor);
  void gmp_inputs_vjp();
  void backward(const ActiveTerms& a, Eigen::VectorXf* g_zl, Eigen::VectorXf* g_zg);

  const runtime::NemfRuntime* model_;
  runtime::Kinematics kinematics_;
  Eigen::Vector3f root_forward_;
  bool gradient_ = false;  // whether the evaluation in progress accumulates gradients
  Eigen::VectorXd frames_;
  runtime::DecoderWorkspace decoder_ws_;
  runtime::GmpWorkspace gmp_ws_;
  // The decode's rows: the whole window when a dense term is active, else the key frames.
  runtime::MatrixRXf sixd_, rotations_, positions_, globals_, zero_root_;
  runtime::MatrixRXf headings_, gmp_in_, gmp_out_, path_;
  // Their gradients.
  runtime::MatrixRXf g_rotations_, g_positions_, g_headings_, g_gmp_out_, g_gmp_in_, g_path_;
  runtime::MatrixRXf g_local_, g_root_, g_sixd_;
};

}  // namespace mf
