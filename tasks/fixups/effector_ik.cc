#include "tasks/fixups/effector_ik.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "tasks/fixups/two_bone_ik.h"

namespace mf {
namespace {

// Out of the reach of a two-bone chain (top, mid, joint) at `frame`: the
// change that brings the target within reach, applied at `frame` and, with the
// weights w, at its neighbours. With `swing` and a chain that does not hang
// from the root, the chain's parent (a shoulder) swings the joint toward the
// target; otherwise (a leg, or a target still beyond the swung arm) the root
// moves by the shortfall along the top-to-target direction (the hips dip or
// lean). A tenth of a millimetre inside the reach is kept as margin. Returns
// false when the target is already within reach.
bool extend_reach(const Motion& m, const GlobalPose& pose, int frame, int top, int mid, int joint,
                  const Eigen::Vector3d& target, bool swing, Eigen::Vector3d* root_shift,
                  Eigen::Quaterniond* parent_swing) {
  const double reach = (pose.position(frame, mid) - pose.position(frame, top)).norm() +
                       (pose.position(frame, joint) - pose.position(frame, mid)).norm() - 2e-4;
  const Eigen::Vector3d to_target = target - pose.position(frame, top);
  const double distance = to_target.norm();
  *root_shift = Eigen::Vector3d::Zero();
  *parent_swing = Eigen::Quaterniond::Identity();
  if (distance <= reach || distance < 1e-9) return false;
  const int parent = m.skeleton.parents[top];
  if (parent <= 0 || !swing) {
    *root_shift = to_target * ((distance - reach) / distance);
  } else {
    const Eigen::Vector3d P = pose.position(frame, parent);
    *parent_swing = Eigen::Quaterniond::FromTwoVectors(pose.position(frame, joint) - P, target - P);
  }
  return true;
}

// One target (see the header); extend_reach() brings it within reach.
void reach_effector(const MotionConstraints& c, const EffectorTarget& e, int falloff, Motion* out) {
  const Skeleton& skel = out->skeleton;
  const int N = out->num_frames();
  if (e.weight <= 0) return;
  const int j = e.joint, mid = skel.parents[j];
  const int top = mid > 0 ? skel.parents[mid] : -1;
  if (top <= 0) return;
  std::vector<char> fixed(N, 0);
  for (size_t i = 0; i < c.keys.size(); ++i) {
    if (c.key_has_joint(i, top) || c.key_has_joint(i, mid) || c.key_has_joint(i, j)) fixed[c.keys[i].frame] = 1;
  }
  if (fixed[e.frame]) return;  // the pose there is given
  auto falloff_weight = [&](int d) { return 0.5 * (1.0 + std::cos(M_PI * d / (falloff + 1.0))); };
  GlobalPose pose = forward_kinematics(*out);
  for (int attempt = 0; attempt < 3; ++attempt) {
    Eigen::Vector3d shift;
    Eigen::Quaterniond swing;
    if (!extend_reach(*out, pose, e.frame, top, mid, j, e.position, attempt == 0, &shift, &swing)) break;
    const bool swung = shift.isZero();
    const int parent = skel.parents[top], grand = parent > 0 ? skel.parents[parent] : -1;
    // Frames whose keys fix what the extension changes: the chain, and the
    // root position (a shift) or the chain's parent (a swing).
    std::vector<char> kept = fixed;
    for (size_t i = 0; i < c.keys.size(); ++i) {
      if (swung ? c.key_has_joint(i, parent) : c.keys[i].root_position) kept[c.keys[i].frame] = 1;
    }
    if (kept[e.frame]) break;
    for (int f = std::max(0, e.frame - falloff); f <= std::min(N - 1, e.frame + falloff); ++f) {
      const int d = std::abs(f - e.frame);
      bool blocked = false;  // stop at a kept frame, as the chain's falloff does
      for (int g = std::min(f, e.frame); g <= std::max(f, e.frame); ++g) blocked = blocked || kept[g];
      if (blocked) continue;
      const double w = falloff_weight(d);
      if (!swung) {
        out->root_positions[f] += w * shift;
      } else {
        const Eigen::Quaterniond global = pose.rotation(f, parent);
        const Eigen::Quaterniond up = grand >= 0 ? pose.rotation(f, grand) : Eigen::Quaterniond::Identity();
        const Eigen::Quaterniond turned = Eigen::Quaterniond::Identity().slerp(w, swing) * global;
        out->rotation(f, parent) = (up.conjugate() * turned).normalized();
      }
    }
    pose = forward_kinematics(*out);
  }
  const Eigen::Vector3d delta = e.position - pose.position(e.frame, j);
  for (int dir : {-1, 1}) {
    for (int d = dir < 0 ? 0 : 1; d <= falloff; ++d) {
      const int f = e.frame + dir * d;
      if (f < 0 || f >= N || fixed[f]) break;
      two_bone_ik(out, &pose, f, top, mid, j, pose.position(f, j) + falloff_weight(d) * delta);
    }
  }
}

}  // namespace

void reach_effectors(const MotionConstraints& c, int falloff, Motion* out) {
  // A second pass puts back what a later target's root shift moved of an
  // earlier target's joint.
  for (int pass = 0; pass < 2; ++pass) {
    for (const EffectorTarget& e : c.effectors) reach_effector(c, e, falloff, out);
  }
}

}  // namespace mf
