#include "prior/runtime/local_features.h"

#include <algorithm>
#include <string>

#include "prior/motion/errors.h"
#include "prior/motion/rotation_kernels.h"

namespace mf::runtime {
namespace {

using Matrix3 = Eigen::Matrix<float, 3, 3, Eigen::RowMajor>;
using ConstMap3 = Eigen::Map<const Matrix3>;

// The 6D of a row-major rotation: its first two columns (m00 m10 m20 m01 m11 m21).
void sixd_of(const float* m, float* out) {
  const float d[6] = {m[0], m[3], m[6], m[1], m[4], m[7]};
  std::copy(d, d + 6, out);
}

}  // namespace

void heading_free_positions(const Kinematics& kinematics, ConstMatrixRef local_rotations,
                            const Eigen::Vector3f& root_forward, MatrixRXf* positions, MatrixRXf* globals) {
  // The root's rotation with its heading removed (H^T R), then FK from the origin.
  const Eigen::Index T = local_rotations.rows();
  MatrixRXf free = local_rotations;
  for (Eigen::Index t = 0; t < T; ++t) {
    Matrix3 h;
    kernels::heading_rotation(local_rotations.row(t).data(), root_forward.data(), h.data());
    Eigen::Map<Matrix3>(&free(t, 0)) = h.transpose() * ConstMap3(local_rotations.row(t).data());
  }
  kinematics.forward(free, MatrixRXf::Zero(T, 3), positions, globals);
}

void local_features(const Kinematics& kinematics, ConstMatrixRef local_rotations, const Eigen::Vector3f& root_forward,
                    double fps, MatrixRXf* features, MatrixRXf* root6d) {
  const int J = kinematics.joints();
  const Eigen::Index T = local_rotations.rows();
  if (T < 1 || local_rotations.cols() != J * 9)
    throw InputError("local_features: expected local rotations [T >= 1, " + std::to_string(J * 9) + "]");
  MatrixRXf positions, globals;
  heading_free_positions(kinematics, local_rotations, root_forward, &positions, &globals);
  features->resize(T, J * 15);
  root6d->resize(T, 6);
  const float rate = static_cast<float>(fps);
  for (Eigen::Index t = 0; t < T; ++t) {
    const Eigen::Index prev = t > 0 ? t - 1 : t, next = t + 1 < T ? t + 1 : t;
    const float span = T < 2 ? 0.0f : (t == 0 || t == T - 1 ? 1.0f : 2.0f);
    sixd_of(local_rotations.row(t).data(), &(*root6d)(t, 0));
    for (int j = 0; j < J; ++j) {
      float* f = &(*features)(t, j * 15);
      for (int i = 0; i < 3; ++i) {
        f[i] = positions(t, j * 3 + i);
        f[3 + i] = span > 0 ? (positions(next, j * 3 + i) - positions(prev, j * 3 + i)) * rate / span : 0.0f;
      }
      sixd_of(&globals(t, j * 9), f + 6);
      // The rotation vector of the small relative rotation next * prev^T, via its skew part.
      const Matrix3 r = ConstMap3(&globals(next, j * 9)) * ConstMap3(&globals(prev, j * 9)).transpose();
      const float skew[3] = {0.5f * (r(2, 1) - r(1, 2)), 0.5f * (r(0, 2) - r(2, 0)), 0.5f * (r(1, 0) - r(0, 1))};
      for (int i = 0; i < 3; ++i) f[12 + i] = span > 0 ? skew[i] * rate / span : 0.0f;
    }
  }
}

}  // namespace mf::runtime
