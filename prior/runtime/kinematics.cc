#include "prior/runtime/kinematics.h"

#include <string>

#include "prior/motion/errors.h"
#include "prior/motion/kinematics_kernels.h"

namespace mf::runtime {

namespace {

void check_rows(ConstMatrixRef m, Eigen::Index rows, Eigen::Index cols, const char* what) {
  if (m.rows() != rows || m.cols() != cols)
    throw InputError(std::string("forward kinematics: ") + what + " must be [" + std::to_string(rows) + ", " +
                     std::to_string(cols) + "], got [" + std::to_string(m.rows()) + ", " + std::to_string(m.cols()) +
                     "]");
}

}  // namespace

Kinematics::Kinematics(const Skeleton& skeleton) : parents_(skeleton.parents) {
  skeleton.validate();
  for (const Eigen::Vector3d& o : skeleton.offsets) {
    for (int k = 0; k < 3; ++k) offsets_.push_back(static_cast<float>(o[k]));
  }
}

void Kinematics::forward(ConstMatrixRef local, ConstMatrixRef root, MatrixRXf* positions, MatrixRXf* global) const {
  const Eigen::Index T = local.rows(), J = joints();
  check_rows(local, T, J * 9, "local rotations");
  check_rows(root, T, 3, "root positions");
  positions->resize(T, J * 3);
  global->resize(T, J * 9);
  // Rows of a Ref may be strided: one frame at a time.
  for (Eigen::Index t = 0; t < T; ++t) {
    kernels::fk_forward(local.row(t).data(), root.row(t).data(), offsets_.data(), parents_.data(), J, 0, 1,
                        &(*positions)(t, 0), &(*global)(t, 0));
  }
}

void Kinematics::vjp(ConstMatrixRef local, ConstMatrixRef global, ConstMatrixRef g_positions, const MatrixRXf* g_global,
                     MatrixRXf* g_local, MatrixRXf* g_root) const {
  const Eigen::Index T = local.rows(), J = joints();
  check_rows(local, T, J * 9, "local rotations");
  check_rows(global, T, J * 9, "global rotations");
  check_rows(g_positions, T, J * 3, "the positions' gradient");
  if (g_global) check_rows(*g_global, T, J * 9, "the global rotations' gradient");
  g_local->resize(T, J * 9);
  g_root->resize(T, 3);
  std::vector<float> gp(J * 3), gr(J * 9);
  for (Eigen::Index t = 0; t < T; ++t) {
    kernels::fk_backward(local.row(t).data(), offsets_.data(), global.row(t).data(), g_positions.row(t).data(),
                         g_global ? &(*g_global)(t, 0) : nullptr, parents_.data(), J, 0, 1, &(*g_local)(t, 0),
                         &(*g_root)(t, 0), static_cast<float*>(nullptr), gp, gr);
  }
}

}  // namespace mf::runtime
