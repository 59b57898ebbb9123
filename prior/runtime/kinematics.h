// Forward kinematics on Eigen over the frames of a window, with its
// vector-Jacobian product: kinematics_torch.h's forward_kinematics through
// the same per-frame kernels (prior/motion/kinematics_kernels.h), so both give
// the same bits. Row-major float, one row per frame: local and global
// rotations [T, J * 9] (per joint a row-major 3x3, joint 0's the root's),
// positions [T, J * 3], root positions [T, 3]. Units and conventions as in
// prior/motion/skeleton.h.
#pragma once

#include <vector>

#include "prior/motion/skeleton.h"
#include "prior/runtime/tensor_ops.h"

namespace mf::runtime {

/// One skeleton's parents and offsets, in float; immutable, shareable.
class Kinematics {
 public:
  /// Throws mf::InputError on an invalid skeleton (Skeleton::validate()).
  explicit Kinematics(const Skeleton& skeleton);

  int joints() const { return static_cast<int>(parents_.size()); }

  /// Global joint positions [T, J * 3] and rotations [T, J * 9] (both
  /// resized) of local rotations `local` [T, J * 9] with the root at `root`
  /// [T, 3].
  void forward(ConstMatrixRef local, ConstMatrixRef root, MatrixRXf* positions, MatrixRXf* global) const;

  /// The gradients with respect to `local` [T, J * 9] and `root` [T, 3]
  /// (resized) of an energy whose gradients with respect to forward()'s
  /// positions are g_positions [T, J * 3] and, unless null, with respect to
  /// its global rotations g_global [T, J * 9]; `global` is forward()'s.
  void vjp(ConstMatrixRef local, ConstMatrixRef global, ConstMatrixRef g_positions, const MatrixRXf* g_global,
           MatrixRXf* g_local, MatrixRXf* g_root) const;

 private:
  std::vector<int> parents_;
  std::vector<float> offsets_;  // [J * 3]
};

}  // namespace mf::runtime
