#include "prior/runtime/rotations.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "prior/motion/errors.h"
#include "prior/motion/quaternion_kernels.h"
#include "prior/motion/rotation_kernels.h"

namespace mf::runtime {

Quaternion4f matrix_to_quat(const float* m) { return Eigen::Map<const Quaternion4f>(kernels::MatrixQuat<float>(m).q); }

void quat_to_matrix(const Quaternion4f& q, float* m) { kernels::quat_to_matrix(q.data(), m); }

Quaternion4f quat_slerp(const Quaternion4f& q0, const Quaternion4f& q1, float t) {
  return Eigen::Map<const Quaternion4f>(kernels::Slerp<float>(q0.data(), q1.data(), t).q);
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
