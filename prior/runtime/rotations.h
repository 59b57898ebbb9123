// The 6D -> rotation matrix conversion of the decoder's output on Eigen, with
// its vector-Jacobian product: the Gram-Schmidt of sixd_to_matrix in
// prior/motion/rotations_torch.h, through the same per-element kernels
// (prior/motion/rotation_kernels.h), so both give the same bits. Row-major
// float, one row per frame: 6D [S, J * 6] (per joint m00, m10, m20, m01, m11,
// m21) and matrices [S, J * 9] (per joint a row-major 3x3 acting on column
// vectors). Also the quaternion conversions and the slerp of the keyframe
// interpolation (prior/inbetween/keyframe_net.h), per rotation, in float as
// the libtorch tensor operations compute them.
#pragma once

#include "prior/runtime/tensor_ops.h"

namespace mf::runtime {

/// A unit quaternion (w, x, y, z).
using Quaternion4f = Eigen::Vector4f;

/// The quaternion of a rotation matrix m [9] (row-major), w >= 0, built from
/// the largest of 4w^2, 4x^2, 4y^2, 4z^2, as torch_rot::matrix_to_quat in
/// prior/motion/rotations_torch.h computes it (float; the kernels of
/// prior/motion/quaternion_kernels.h, as the three below).
Quaternion4f matrix_to_quat(const float* m);
/// The rotation matrix m [9] of a quaternion (any length), as torch_rot::quat_to_matrix.
void quat_to_matrix(const Quaternion4f& q, float* m);
/// Shortest-path spherical interpolation at t in [0, 1] (normalised linear
/// interpolation when the quaternions are within a dot of 0.9995), as
/// torch_rot::quat_slerp.
Quaternion4f quat_slerp(const Quaternion4f& q0, const Quaternion4f& q1, float t);

/// rotations [S, J * 9] (resized) of the 6D d6 [S, J * 6].
void sixd_to_matrix(ConstMatrixRef d6, MatrixRXf* rotations);

/// d energy / d d6 [S, J * 6] (resized) from d energy / d rotations
/// [S, J * 9] at sixd_to_matrix(d6).
void sixd_to_matrix_vjp(ConstMatrixRef d6, ConstMatrixRef g_rotations, MatrixRXf* g_d6);

}  // namespace mf::runtime
