#include "prior/runtime/root_path.h"

#include "prior/motion/rotation_kernels.h"

namespace mf::runtime {
namespace {

using Matrix3 = Eigen::Matrix<float, 3, 3, Eigen::RowMajor>;
using ConstMap3 = Eigen::Map<const Matrix3>;

}  // namespace

void gmp_inputs(ConstMatrixRef rotations, ConstMatrixRef positions, const Eigen::Vector3f& root_forward,
                MatrixRXf* headings, MatrixRXf* inputs) {
  const int T = static_cast<int>(rotations.rows()), J = static_cast<int>(rotations.cols() / 9);
  headings->resize(T, 9);
  inputs->resize(T, J * 3 + 6);
  for (int t = 0; t < T; ++t) {
    kernels::heading_rotation(rotations.row(t).data(), root_forward.data(), headings->row(t).data());
    const ConstMap3 h(headings->row(t).data()), root(rotations.row(t).data());
    for (int j = 0; j < J; ++j) {
      inputs->row(t).segment<3>(j * 3) = (h.transpose() * positions.row(t).segment<3>(j * 3).transpose()).transpose();
    }
    const Matrix3 free = h.transpose() * root;
    for (int i = 0; i < 3; ++i) {
      (*inputs)(t, J * 3 + i) = free(i, 0);
      (*inputs)(t, J * 3 + 3 + i) = free(i, 1);
    }
  }
}

void integrate_root_path(ConstMatrixRef headings, ConstMatrixRef gmp_out, double fps, MatrixRXf* path) {
  const int T = static_cast<int>(gmp_out.rows());
  const float step_fps = static_cast<float>(fps);
  path->resize(T, 3);
  double x = 0, z = 0;
  for (int t = 0; t < T; ++t) {
    (*path)(t, 0) = static_cast<float>(x);
    (*path)(t, 1) = gmp_out(t, 3);
    (*path)(t, 2) = static_cast<float>(z);
    const Eigen::Vector3f v = ConstMap3(headings.row(t).data()) * gmp_out.row(t).head<3>().transpose();
    x += v.x() / step_fps;
    z += v.z() / step_fps;
  }
}

}  // namespace mf::runtime
