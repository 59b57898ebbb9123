#include "tasks/fixups/two_bone_ik.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace mf {

void two_bone_ik(Motion* m, GlobalPose* pose, int frame, int hip, int knee, int ankle, const Eigen::Vector3d& target) {
  // Named for a leg: hip = top, knee = mid, ankle = end.
  const int J = m->num_joints();
  auto gpos = [&](int j) -> Eigen::Vector3d& { return pose->positions[static_cast<size_t>(frame) * J + j]; };
  auto grot = [&](int j) -> Eigen::Quaterniond& { return pose->rotations[static_cast<size_t>(frame) * J + j]; };
  const Eigen::Vector3d H = gpos(hip), K = gpos(knee), A = gpos(ankle);
  const double a = (K - H).norm(), b = (A - K).norm();
  if (a < 1e-6 || b < 1e-6) return;
  const double d = std::clamp((target - H).norm(), std::abs(a - b) + 1e-4, a + b - 1e-4);
  const Eigen::Vector3d u = H - K, v = A - K;
  Eigen::Vector3d n = u.cross(v);
  Eigen::Quaterniond knee_delta = Eigen::Quaterniond::Identity();
  if (n.norm() > 1e-8 * a * b) {
    n.normalize();
    const double now = std::acos(std::clamp(u.dot(v) / (a * b), -1.0, 1.0));
    const double want = std::acos(std::clamp((a * a + b * b - d * d) / (2 * a * b), -1.0, 1.0));
    knee_delta = Eigen::Quaterniond(Eigen::AngleAxisd(want - now, n));
  }
  const Eigen::Vector3d A1 = K + knee_delta * v;
  const Eigen::Quaterniond hip_delta = Eigen::Quaterniond::FromTwoVectors(A1 - H, target - H);
  const Eigen::Quaterniond ankle_global = grot(ankle);
  const Eigen::Quaterniond hip_global = (hip_delta * grot(hip)).normalized();
  const Eigen::Quaterniond knee_global = (hip_delta * knee_delta * grot(knee)).normalized();
  const int hip_parent = m->skeleton.parents[hip];
  const Eigen::Quaterniond parent_global = hip_parent >= 0 ? grot(hip_parent) : Eigen::Quaterniond::Identity();
  m->rotation(frame, hip) = (parent_global.conjugate() * hip_global).normalized();
  m->rotation(frame, knee) = (hip_global.conjugate() * knee_global).normalized();
  m->rotation(frame, ankle) = (knee_global.conjugate() * ankle_global).normalized();
  grot(hip) = hip_global;
  grot(knee) = knee_global;
  gpos(knee) = H + hip_delta * (K - H);
  gpos(ankle) = H + hip_delta * (A1 - H);
}

}  // namespace mf
