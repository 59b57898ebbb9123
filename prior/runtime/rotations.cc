#include "prior/runtime/rotations.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "prior/motion/errors.h"
#include "prior/motion/rotation_kernels.h"

namespace mf::runtime {

namespace {

Quaternion4f normalized(const Quaternion4f& q) { return q * (1.0f / std::sqrt(std::max(q.squaredNorm(), 1e-24f))); }

}  // namespace

Quaternion4f matrix_to_quat(const float* m) {
  const float m00 = m[0], m01 = m[1], m02 = m[2], m10 = m[3], m11 = m[4], m12 = m[5], m20 = m[6], m21 = m[7],
              m22 = m[8];
  const float four_sq[4] = {1 + m00 + m11 + m22, 1 + m00 - m11 - m22, 1 - m00 + m11 - m22, 1 - m00 - m11 + m22};
  const int best = static_cast<int>(std::max_element(four_sq, four_sq + 4) - four_sq);
  const float a = four_sq[best] > 0 ? std::sqrt(four_sq[best]) : 0.0f;  // 2 |q_best|
  Quaternion4f c;
  switch (best) {
    case 0: c << a * a, m21 - m12, m02 - m20, m10 - m01; break;
    case 1: c << m21 - m12, a * a, m10 + m01, m02 + m20; break;
    case 2: c << m02 - m20, m10 + m01, a * a, m12 + m21; break;
    default: c << m10 - m01, m20 + m02, m21 + m12, a * a; break;
  }
  const Quaternion4f q = normalized(c / std::max(2 * a, 0.1f));
  return q[0] < 0 ? Quaternion4f(-q) : q;
}

void quat_to_matrix(const Quaternion4f& q, float* m) {
  const float w = q[0], x = q[1], y = q[2], z = q[3];
  const float s = 2.0f / std::max(q.cwiseProduct(q).sum(), 1e-24f);
  const float xx = x * x * s, yy = y * y * s, zz = z * z * s, xy = x * y * s, xz = x * z * s, yz = y * z * s;
  const float wx = w * x * s, wy = w * y * s, wz = w * z * s;
  const float r[9] = {1 - yy - zz, xy - wz, xz + wy, xy + wz, 1 - xx - zz, yz - wx, xz - wy, yz + wx, 1 - xx - yy};
  std::copy(r, r + 9, m);
}

Quaternion4f quat_slerp(const Quaternion4f& q0, const Quaternion4f& q1, float t) {
  const Quaternion4f a = normalized(q0), b = normalized(q1);
  float dot = a.cwiseProduct(b).sum();
  const float flip = dot < 0 ? -1.0f : 1.0f;
  const Quaternion4f bs = b * flip;
  dot = dot * flip;
  if (dot > 0.9995f) return normalized(a * (1 - t) + bs * t);  // the threshold of torch_rot::quat_slerp
  const float theta = std::acos(std::clamp(dot, -1.0f, 1.0f));
  const float inv_sin = 1.0f / std::sin(theta);
  return normalized(a * (std::sin((1 - t) * theta) * inv_sin) + bs * (std::sin(t * theta) * inv_sin));
}

void sixd_to_matrix(ConstMatrixRef d6, MatrixRXf* rotations) {
  if (d6.cols() % 6 != 0)
    throw InputError("sixd_to_matrix: expected 6D [S, J * 6], got " + std::to_string(d6.cols()) + " columns");
  const Eigen::Index S = d6.rows(), J = d6.cols() / 6;
  rotations->resize(S, J * 9);
  for (Eigen::Index s = 0; s < S; ++s) {
    for (Eigen::Index j = 0; j < J; ++j) kernels::sixd_to_matrix(d6.row(s).data() + j * 6, &(*rotations)(s, j * 9));
  }
}

void sixd_to_matrix_vjp(ConstMatrixRef d6, ConstMatrixRef g_rotations, MatrixRXf* g_d6) {
  const Eigen::Index S = d6.rows(), J = d6.cols() / 6;
  if (d6.cols() % 6 != 0 || g_rotations.rows() != S || g_rotations.cols() != J * 9)
    throw InputError("sixd_to_matrix_vjp: expected 6D [S, J * 6] and its matrices' gradient [S, J * 9]");
  g_d6->resize(S, J * 6);
  for (Eigen::Index s = 0; s < S; ++s) {
    for (Eigen::Index j = 0; j < J; ++j) {
      kernels::sixd_to_matrix_vjp(d6.row(s).data() + j * 6, g_rotations.row(s).data() + j * 9, &(*g_d6)(s, j * 6));
    }
  }
}

}  // namespace mf::runtime
