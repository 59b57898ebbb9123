// The on-output residual blending of the latent energy (EnergyWeights::on_output;
// blend_residuals in tasks/latent/energies.cc) on Eigen, with its
// vector-Jacobian product: the motion as complete_motion() returns it, the
// residual of each key (target * decoded^T as a quaternion, w >= 0; the root
// position's difference) spread over the window with smoothstep weights
// (SLERP between the keys around a frame that constrain the joint, LERP for the
// root position) and applied on the left (added). The quaternion
// conversions follow rotations_torch.h's matrix_to_quat, quat_slerp and
// quat_to_matrix formula for formula, in double. Torch-free.
#pragma once

#include <vector>

#include "prior/runtime/tensor_ops.h"
#include "tasks/constraints/residual_bracket.h"

namespace mf {

struct RuntimeWindowProblem;

/// The blending of one problem's keys into a dense decode, with the buffers
/// of its last forward() (reused).
class RuntimeResidualBlend {
 public:
  /// The blended local rotations `out_rotations` [T, J * 9] and root path
  /// `out_path` [T, 3] (resized) of `rotations` [T, J * 9] and `path` [T, 3],
  /// the whole window of `problem`, which has keys.
  void forward(const RuntimeWindowProblem& problem, runtime::ConstMatrixRef rotations, runtime::ConstMatrixRef path,
               runtime::MatrixRXf* out_rotations, runtime::MatrixRXf* out_path);

  /// Adds to g_rotations [T, J * 9] and g_path [T, 3] the gradients of an
  /// energy whose gradients with respect to the last forward()'s outputs are
  /// g_out_rotations and g_out_path; `rotations` is that forward()'s.
  void vjp(const RuntimeWindowProblem& problem, runtime::ConstMatrixRef rotations,
           runtime::ConstMatrixRef g_out_rotations, runtime::ConstMatrixRef g_out_path,
           runtime::MatrixRXf* g_rotations, runtime::MatrixRXf* g_path) const;

 private:
  void brackets(const RuntimeWindowProblem& problem, int J);
  void blend_rotations(const RuntimeWindowProblem& problem, runtime::ConstMatrixRef rotations,
                       runtime::MatrixRXf* out_rotations);

  std::vector<KeyBracket> joints_;  // [T * J], frame-major
  std::vector<KeyBracket> root_;    // [T]
  std::vector<double> key_quats_;   // [K * J * 4] the keys' residuals
  std::vector<double> quats_;       // [T * J * 4] the blended residuals (where a key constrains the joint)
};

}  // namespace mf
