#include "tasks/constraint_report.h"

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

ConstraintReport measure_constraints(const Motion& input, const MotionConstraints& c, const Motion& motion) {
  return ConstraintReport{key_error(input, c, motion), effector_error(motion, c), contact_error(motion, c)};
}

}  // namespace mf
