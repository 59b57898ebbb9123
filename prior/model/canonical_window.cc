#include "prior/model/canonical_window.h"

#include <cmath>

#include <Eigen/Geometry>

#include "prior/motion/errors.h"

namespace mf {
namespace {

using RowsD = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

Eigen::Matrix3d rot_y(double yaw) { return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix(); }

double heading_yaw(const Eigen::Quaterniond& root_rotation, const Eigen::Vector3d& forward) {
  Eigen::Vector3d f = root_rotation * forward;
  if (f.x() * f.x() + f.z() * f.z() < 1e-12) return 0.0;
  return std::atan2(f.x(), f.z());
}

}  // namespace

GroundTransform canonical_transform(const Motion& motion, int anchor_frame, const RigInfo& rig) {
  GroundTransform t;
  t.yaw = heading_yaw(motion.rotation(anchor_frame, 0), rig.root_forward);
  t.x = motion.root_positions[anchor_frame].x();
  t.z = motion.root_positions[anchor_frame].z();
  return t;
}

WindowMatrices window_matrices(const Motion& motion, int begin, int length, const RigInfo& rig, int anchor) {
  const int J = motion.num_joints();
  if (begin < 0 || length < 1 || begin + length > motion.num_frames() || anchor < 0 || anchor >= length) {
    throw InputError("window out of the motion's range");
  }
  GroundTransform g = canonical_transform(motion, begin + anchor, rig);
  const Eigen::Matrix3d unturn = rot_y(-g.yaw);
  WindowMatrices out;
  out.local_rotations.resize(length, J * 9);
  out.root_positions.resize(length, 3);
  float* r = out.local_rotations.data();
  float* p = out.root_positions.data();
  for (int t = 0; t < length; ++t) {
    for (int j = 0; j < J; ++j) {
      Eigen::Matrix3d m = motion.rotation(begin + t, j).normalized().toRotationMatrix();
      if (j == 0) m = unturn * m;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) *r++ = static_cast<float>(m(a, b));
    }
    Eigen::Vector3d x = unturn * (motion.root_positions[begin + t] - Eigen::Vector3d(g.x, 0, g.z));
    for (int a = 0; a < 3; ++a) *p++ = static_cast<float>(x[a]);
  }
  return out;
}

void write_window(const Eigen::Ref<const RowsD>& local_rotations, const Eigen::Ref<const RowsD>& root_positions,
                  const GroundTransform& transform, Motion* motion, int begin) {
  const int T = static_cast<int>(local_rotations.rows());
  const int J = static_cast<int>(local_rotations.cols() / 9);
  if (local_rotations.cols() != J * 9 || root_positions.rows() != T || root_positions.cols() != 3 ||
      J != motion->num_joints() || begin < 0 || begin + T > motion->num_frames()) {
    throw InputError("window does not fit the motion");
  }
  const Eigen::Matrix3d turn = rot_y(transform.yaw);
  for (int t = 0; t < T; ++t) {
    const double* r = local_rotations.row(t).data();
    for (int j = 0; j < J; ++j) {
      Eigen::Matrix3d m;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) m(a, b) = *r++;
      if (j == 0) m = turn * m;
      motion->rotation(begin + t, j) = Eigen::Quaterniond(m).normalized();
    }
    const Eigen::Vector3d x(root_positions(t, 0), root_positions(t, 1), root_positions(t, 2));
    motion->root_positions[begin + t] = turn * x + Eigen::Vector3d(transform.x, 0, transform.z);
  }
}

}  // namespace mf
