// Batched, differentiable rotation conversions on torch tensors (float), for
// training and latent solving. Same conventions as rotations.h: quaternions
// (w, x, y, z) in the last dimension, matrices [..., 3, 3] acting on column
// vectors, 6D = first two columns (m00, m10, m20, m01, m11, m21).
// All functions broadcast over leading dimensions and are autograd-safe
// (no NaN gradients at identity or at 180 degrees).
#pragma once

#include <ATen/core/Tensor.h>

namespace mf::torch_rot {

at::Tensor quat_normalize(const at::Tensor& q);                        // [...,4]
at::Tensor quat_multiply(const at::Tensor& a, const at::Tensor& b);    // [...,4]
at::Tensor quat_conjugate(const at::Tensor& q);                        // [...,4]
at::Tensor quat_rotate(const at::Tensor& q, const at::Tensor& v);      // [...,4],[...,3] -> [...,3]
at::Tensor quat_to_matrix(const at::Tensor& q);                        // [...,4] -> [...,3,3]
at::Tensor matrix_to_quat(const at::Tensor& m);                        // [...,3,3] -> [...,4], w >= 0
at::Tensor matrix_to_sixd(const at::Tensor& m);                        // [...,3,3] -> [...,6]
at::Tensor sixd_to_matrix(const at::Tensor& d6);                       // [...,6] -> [...,3,3]
/// Shortest-path SLERP; t broadcasts against q0[..., :1].
at::Tensor quat_slerp(const at::Tensor& q0, const at::Tensor& q1, const at::Tensor& t);
/// Geodesic angle (radians) between rotation matrices, [...,3,3] x2 -> [...].
/// Differentiable everywhere, including identical inputs.
at::Tensor geodesic_angle(const at::Tensor& m0, const at::Tensor& m1);
/// Makes quaternion signs continuous along dimension `dim` (each q flipped to
/// agree with its predecessor). Not differentiable through the sign choice.
at::Tensor quat_make_continuous(const at::Tensor& q, int64_t dim);

}  // namespace mf::torch_rot
