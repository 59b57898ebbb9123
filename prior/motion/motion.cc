#include "prior/motion/motion.h"

#include <cmath>
#include <string>

#include "prior/motion/errors.h"

namespace mf {

Motion Motion::identity(const Skeleton& skeleton, int frames, double fps) {
  if (frames < 0) throw InputError("motion frame count must not be negative, got " + std::to_string(frames));
  Motion m;
  m.skeleton = skeleton;
  m.fps = fps;
  m.rotations.assign(static_cast<size_t>(frames) * skeleton.num_joints(), Eigen::Quaterniond::Identity());
  m.root_positions.assign(frames, Eigen::Vector3d::Zero());
  return m;
}

Motion Motion::slice(int begin, int end) const {
  if (begin < 0 || end < begin || end > num_frames())
    throw InputError("frame range [" + std::to_string(begin) + ", " + std::to_string(end) +
                     ") is outside the motion's " + std::to_string(num_frames()) + " frames");
  Motion m;
  m.skeleton = skeleton;
  m.fps = fps;
  const size_t J = num_joints();
  m.rotations.assign(rotations.begin() + begin * J, rotations.begin() + end * J);
  m.root_positions.assign(root_positions.begin() + begin, root_positions.begin() + end);
  return m;
}

void Motion::validate() const {
  skeleton.validate();
  if (!(std::isfinite(fps) && fps > 0)) throw InputError("motion fps must be positive and finite");
  const size_t expected = root_positions.size() * static_cast<size_t>(num_joints());
  if (rotations.size() != expected)
    throw InputError("motion has " + std::to_string(rotations.size()) + " rotations, expected " +
                     std::to_string(expected) + " (" + std::to_string(num_frames()) + " frames x " +
                     std::to_string(num_joints()) + " joints)");
  for (size_t i = 0; i < root_positions.size(); ++i)
    if (!root_positions[i].allFinite())
      throw InputError("motion root position of frame " + std::to_string(i) + " is not finite");
  for (size_t i = 0; i < rotations.size(); ++i) {
    const Eigen::Vector4d c = rotations[i].coeffs();
    if (!c.allFinite() || c.norm() < 1e-6)
      throw InputError("motion rotation of frame " + std::to_string(i / num_joints()) + ", joint '" +
                       skeleton.names[i % num_joints()] + "' is not a finite non-zero quaternion");
  }
}

GlobalPose forward_kinematics(const Motion& motion) {
  GlobalPose pose;
  pose.frames = motion.num_frames();
  pose.joints = motion.num_joints();
  const size_t n = static_cast<size_t>(pose.frames) * pose.joints;
  pose.positions.resize(n);
  pose.rotations.resize(n);
  const std::vector<int>& parents = motion.skeleton.parents;
  for (int f = 0; f < pose.frames; ++f) {
    const size_t row = static_cast<size_t>(f) * pose.joints;
    for (int j = 0; j < pose.joints; ++j) {
      const Eigen::Quaterniond local = motion.rotation(f, j).normalized();
      const int p = parents[j];
      if (p < 0) {
        pose.positions[row + j] = motion.root_positions[f];
        pose.rotations[row + j] = local;
      } else {
        pose.positions[row + j] = pose.positions[row + p] + pose.rotations[row + p] * motion.skeleton.offsets[j];
        pose.rotations[row + j] = (pose.rotations[row + p] * local).normalized();
      }
    }
  }
  return pose;
}

}  // namespace mf
