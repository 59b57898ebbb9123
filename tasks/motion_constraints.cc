#include "tasks/motion_constraints.h"

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
  return j.empty() || std::binary_search(j.begin(), j.end(), joint);
}

bool MotionConstraints::key_fixes_root(size_t k) const { return keys[k].root_position && key_has_joint(k, 0); }

void MotionConstraints::validate(int frames, int joints) const {
  auto range = [&](int f) { return "(the motion has " + std::to_string(frames) + " frames)"; };
  bool anchor = false;
  for (size_t k = 0; k < keys.size(); ++k) {
    const PoseKey& key = keys[k];
    if (key.frame < 0 || key.frame >= frames)
      throw InputError("key frame " + std::to_string(key.frame) + " is out of range " + range(key.frame));
    if (k > 0 && key.frame <= keys[k - 1].frame)
      throw InputError("key frames must be strictly increasing (" + std::to_string(keys[k - 1].frame) +
                       " is followed by " + std::to_string(key.frame) + ")");
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
  if (!anchor) {
    throw InputError(
        "at least one key must give the root's rotation and position (the solver places the motion relative to it)");
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
  return out;
}

}  // namespace mf
