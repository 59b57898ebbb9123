// The 6D -> rotation matrix conversion of the decoder's output on Eigen, with
// its vector-Jacobian product: the Gram-Schmidt of sixd_to_matrix in
// prior/motion/rotations_torch.h, through the same per-element kernels
// (prior/motion/rotation_kernels.h), so both give the same bits. Row-major
// float, one row per frame: 6D [S, J * 6] (per joint m00, m10, m20, m01, m11,
// m21) and matrices [S, J * 9] (per joint a row-major 3x3 acting on column
// vectors).
#pragma once

#include "prior/runtime/tensor_ops.h"

namespace mf::runtime {

/// rotations [S, J * 9] (resized) of the 6D d6 [S, J * 6].
void sixd_to_matrix(ConstMatrixRef d6, MatrixRXf* rotations);

/// d energy / d d6 [S, J * 6] (resized) from d energy / d rotations
/// [S, J * 9] at sixd_to_matrix(d6).
void sixd_to_matrix_vjp(ConstMatrixRef d6, ConstMatrixRef g_rotations, MatrixRXf* g_d6);

}  // namespace mf::runtime
