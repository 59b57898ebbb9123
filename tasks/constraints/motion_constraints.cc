#include "tasks/constraints/motion_constraints.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "prior/motion/errors.h"

namespace mf {

MotionConstraints MotionConstraints::full_pose(const std::vector<int>& frames) {
  MotionConstraints c;
  c.keys.reserve(frames.size());
  for (int f : frames) {
    PoseKey k;
    k.frame = f;
    c.keys.push_back(k);
  }
  return c;
}

bool MotionConstraints::key_has_joint(size_t k, int joint) const {
  const std::vector<int>& j = keys[k].joints;
  if (!keys[k].rotations) return false;
  return j.empty() || std::binary_search(j.begin(), j.end(), joint);
}

bool MotionConstraints::key_fixes_root(size_t k) const { return keys[k].root_position && key_has_joint(k, 0); }

bool MotionConstraints::fixes_root_position(int frame) const {
  for (const PoseKey& k : keys) {
    if (k.frame == frame && k.root_position) return true;
  }
  return false;
}

std::vector<TrajectoryPoint> MotionConstraints::followed_trajectory() const {
  std::vector<TrajectoryPoint> out;
  size_t k = 0;  // keys and rows are both sorted by frame
  for (const TrajectoryPoint& p : trajectory) {
    while (k < keys.size() && keys[k].frame < p.frame) ++k;
    if (!(k < keys.size() && keys[k].frame == p.frame && keys[k].root_position)) out.push_back(p);
  }
  return out;
}

bool MotionConstraints::beyond_full_poses() const {
  if (!effectors.empty() || !contacts.empty() || !trajectory.empty()) return true;
  for (const PoseKey& k : keys) {
    if (!k.joints.empty() || !k.root_position || !k.rotations) return true;
  }
  return false;
}

void check_keyframe_order(int previous, int frame) {
  if (frame == previous) throw InputError("keyframe " + std::to_string(frame) + " is given twice");
  if (frame < previous)
    throw InputError("keyframes must be in increasing order (" + std::to_string(previous) + " is followed by " +
                     std::to_string(frame) + ")");
}

void MotionConstraints::validate(int frames, int joints) const {
  auto range = [&](int f) { return "(the motion has " + std::to_string(frames) + " frames)"; };
  bool anchor = false;
  for (size_t k = 0; k < keys.size(); ++k) {
    const PoseKey& key = keys[k];
    if (key.frame < 0 || key.frame >= frames)
      throw InputError("key frame " + std::to_string(key.frame) + " is out of range " + range(key.frame));
    if (k > 0) check_keyframe_order(keys[k - 1].frame, key.frame);
    if (!key.rotations && !key.joints.empty())
      throw InputError("key at frame " + std::to_string(key.frame) + ": joints listed on a key without rotations");
    if (!key.rotations && !key.root_position)
      throw InputError("key at frame " + std::to_string(key.frame) + " constrains nothing");
    for (size_t i = 0; i < key.joints.size(); ++i) {
      const int j = key.joints[i];
      if (j < 0 || j >= joints)
        throw InputError("key at frame " + std::to_string(key.frame) + ": joint " + std::to_string(j) +
                         " is out of range (the skeleton has " + std::to_string(joints) + " joints)");
      if (i > 0 && j <= key.joints[i - 1])
        throw InputError("key at frame " + std::to_string(key.frame) +
                         ": constrained joints must be listed once each, in increasing order");
    }
    anchor = anchor || key_fixes_root(k);
  }
  for (const EffectorTarget& e : effectors) {
    if (e.frame < 0 || e.frame >= frames)
      throw InputError("end-effector target frame " + std::to_string(e.frame) + " is out of range " + range(e.frame));
    if (e.joint < 0 || e.joint >= joints)
      throw InputError("end-effector target joint " + std::to_string(e.joint) + " is out of range (the skeleton has " +
                       std::to_string(joints) + " joints)");
    if (!e.position.allFinite()) throw InputError("end-effector target position is not finite");
    if (!(std::isfinite(e.weight) && e.weight >= 0.0))
      throw InputError("end-effector target weight must be finite and non-negative");
  }
  validate_contacts(frames, joints);
  validate_trajectory(frames);
  if (!anchor) {
    throw InputError(
        "at least one key must give the root's rotation and position (the solver places the motion relative to it)");
  }
}

void MotionConstraints::check_values(const Motion& input) const {
  for (size_t k = 0; k < keys.size(); ++k) {
    const int f = keys[k].frame;
    for (int j = 0; j < input.num_joints(); ++j) {
      if (!key_has_joint(k, j)) continue;
      const Eigen::Quaterniond& q = input.rotation(f, j);
      if (!q.coeffs().allFinite() || q.norm() < 1e-6)
        throw InputError("the rotation of joint " + input.skeleton.names[j] + " at known frame " + std::to_string(f) +
                         " is not a finite, non-zero quaternion");
    }
    if (keys[k].root_position && !input.root_positions[f].allFinite())
      throw InputError("the root position at known frame " + std::to_string(f) + " is not finite");
  }
}

void MotionConstraints::validate_contacts(int frames, int joints) const {
  for (size_t i = 0; i < contacts.size(); ++i) {
    const ContactPin& p = contacts[i];
    const std::string what = "contact " + std::to_string(p.first) + ".." + std::to_string(p.last);
    if (p.joint < 0 || p.joint >= joints)
      throw InputError(what + ": joint " + std::to_string(p.joint) + " is out of range (the skeleton has " +
                       std::to_string(joints) + " joints)");
    if (p.first < 0 || p.last >= frames)
      throw InputError(what + " is out of range (the motion has " + std::to_string(frames) + " frames)");
    if (p.first >= p.last) throw InputError(what + " must span at least two frames (first < last)");
    for (size_t k = 0; k < i; ++k) {
      const ContactPin& q = contacts[k];
      if (q.joint == p.joint && q.first <= p.last && p.first <= q.last)
        throw InputError(what + " overlaps contact " + std::to_string(q.first) + ".." + std::to_string(q.last) +
                         " of the same joint: merge them into one");
    }
  }
}

void MotionConstraints::validate_trajectory(int frames) const {
  for (size_t i = 0; i < trajectory.size(); ++i) {
    const TrajectoryPoint& p = trajectory[i];
    const std::string what = "trajectory row at frame " + std::to_string(p.frame);
    if (p.frame < 0 || p.frame >= frames)
      throw InputError(what + " is out of range (the motion has " + std::to_string(frames) + " frames)");
    if (i > 0 && p.frame <= trajectory[i - 1].frame)
      throw InputError("trajectory frames must be strictly increasing (" + std::to_string(trajectory[i - 1].frame) +
                       " is followed by " + std::to_string(p.frame) + ")");
    if (!std::isfinite(p.x) || !std::isfinite(p.z) || !std::isfinite(p.forward_x) || !std::isfinite(p.forward_z))
      throw InputError(what + ": values must be finite");
    if (std::hypot(p.forward_x, p.forward_z) < 1e-6)
      throw InputError(what + ": the facing direction (forward_x, forward_z) has zero length");
  }
}

MotionConstraints MotionConstraints::slice(int begin, int length) const {
  MotionConstraints out;
  for (const PoseKey& k : keys) {
    if (k.frame < begin || k.frame >= begin + length) continue;
    PoseKey s = k;
    s.frame -= begin;
    out.keys.push_back(s);
  }
  for (const EffectorTarget& e : effectors) {
    if (e.frame < begin || e.frame >= begin + length) continue;
    EffectorTarget s = e;
    s.frame -= begin;
    out.effectors.push_back(s);
  }
  for (const ContactPin& p : contacts) {
    ContactPin s = p;
    s.first = std::max(p.first, begin) - begin;
    s.last = std::min(p.last, begin + length - 1) - begin;
    if (s.first < s.last) out.contacts.push_back(s);
  }
  for (const TrajectoryPoint& p : trajectory) {
    if (p.frame < begin || p.frame >= begin + length) continue;
    TrajectoryPoint s = p;
    s.frame -= begin;
    out.trajectory.push_back(s);
  }
  return out;
}

}  // namespace mf
