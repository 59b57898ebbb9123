#include "tasks/constraints/constraint_report.h"

#include <algorithm>
#include <cmath>

#include "prior/motion/rotations.h"

namespace mf {

ConstraintError key_error(const Motion& input, const MotionConstraints& c, const Motion& motion) {
  ConstraintError err;
  double rot_sum = 0.0, root_sum = 0.0;
  for (int j = 0; j < input.num_joints(); ++j) {
    for (size_t k = 0; k < c.keys.size(); ++k) {
      if (!c.key_has_joint(k, j)) continue;
      const int f = c.keys[k].frame;
      const double deg = geodesic_angle(input.rotation(f, j).normalized(), motion.rotation(f, j)) * 180.0 / M_PI;
      err.rotation_max_deg = std::max(err.rotation_max_deg, deg);
      rot_sum += deg;
      ++err.rotations;
    }
  }
  for (const PoseKey& k : c.keys) {
    if (!k.root_position) continue;
    const double cm = (input.root_positions[k.frame] - motion.root_positions[k.frame]).norm() * 100.0;
    err.root_max_cm = std::max(err.root_max_cm, cm);
    root_sum += cm;
    ++err.roots;
  }
  if (err.rotations) err.rotation_mean_deg = rot_sum / err.rotations;
  if (err.roots) err.root_mean_cm = root_sum / err.roots;
  return err;
}

EffectorError effector_error(const Motion& motion, const MotionConstraints& c) {
  EffectorError e;
  if (c.effectors.empty()) return e;
  const GlobalPose pose = forward_kinematics(motion);
  double sum = 0.0;
  for (const EffectorTarget& t : c.effectors) {
    const double d = (pose.position(t.frame, t.joint) - t.position).norm() * 100.0;
    e.max_cm = std::max(e.max_cm, d);
    sum += d;
    ++e.count;
  }
  e.mean_cm = sum / e.count;
  return e;
}

ContactError contact_error(const Motion& motion, const MotionConstraints& c) {
  ContactError e;
  if (c.contacts.empty()) return e;
  const GlobalPose pose = forward_kinematics(motion);
  double sum = 0.0;
  for (const ContactPin& p : c.contacts) {
    const Eigen::Vector3d start = pose.position(p.first, p.joint);
    for (int f = p.first; f <= p.last; ++f) {
      const double d = (pose.position(f, p.joint) - start).norm() * 100.0;
      e.max_cm = std::max(e.max_cm, d);
      sum += d;
      ++e.frames;
    }
  }
  e.mean_cm = sum / e.frames;
  return e;
}

TrajectoryError trajectory_error(const Motion& motion, const MotionConstraints& c, const Eigen::Vector3d& root_forward) {
  TrajectoryError e;
  double sum = 0.0, facing_sum = 0.0;
  for (const TrajectoryPoint& p : c.followed_trajectory()) {
    const Eigen::Vector3d& x = motion.root_positions[p.frame];
    const double cm = std::hypot(x.x() - p.x, x.z() - p.z) * 100.0;
    // The heading's forward (as heading_rotation(): the root's forward axis on the ground).
    const Eigen::Vector3d f = motion.rotation(p.frame, 0).normalized() * root_forward;
    const double deg = std::abs(std::remainder(std::atan2(f.x(), f.z()) - std::atan2(p.forward_x, p.forward_z),
                                               2.0 * M_PI)) * 180.0 / M_PI;
    e.max_cm = std::max(e.max_cm, cm);
    e.facing_max_deg = std::max(e.facing_max_deg, deg);
    sum += cm;
    facing_sum += deg;
    ++e.rows;
  }
  if (e.rows) {
    e.mean_cm = sum / e.rows;
    e.facing_mean_deg = facing_sum / e.rows;
  }
  return e;
}

ConstraintReport measure_constraints(const Motion& input, const MotionConstraints& c, const Motion& motion,
                                     const Eigen::Vector3d& root_forward) {
  return ConstraintReport{key_error(input, c, motion), effector_error(motion, c), contact_error(motion, c),
                          trajectory_error(motion, c, root_forward)};
}

}  // namespace mf
