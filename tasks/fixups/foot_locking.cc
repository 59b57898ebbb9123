#include "tasks/fixups/foot_locking.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "tasks/fixups/two_bone_ik.h"

namespace mf {
namespace {

struct Leg {
  int hip = -1, knee = -1, ankle = -1;
};

// The leg above `ankle`; false for a toe joint or an ankle without a thigh and
// a shin below the root.
bool leg_above(const Skeleton& skel, int ankle, Leg* leg) {
  std::string name = skel.names[ankle];
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char ch) { return std::tolower(ch); });
  if (name.find("toe") != std::string::npos) return false;
  leg->ankle = ankle;
  leg->knee = skel.parents[ankle];
  leg->hip = leg->knee > 0 ? skel.parents[leg->knee] : -1;
  return leg->hip > 0;
}

// Frames the IK may not change (`fixed`: a key constrains a joint of the leg,
// or an effector target sits on the leg, below it or above its hip) and frames
// whose ankle position is known (`known`: a key gives the whole leg and the root).
void protected_frames(const MotionConstraints& c, const Skeleton& skel, const Leg& leg, int frames,
                      std::vector<char>* fixed, std::vector<char>* known) {
  fixed->assign(frames, 0);
  known->assign(frames, 0);
  for (size_t i = 0; i < c.keys.size(); ++i) {
    const int f = c.keys[i].frame;
    const bool hip = c.key_has_joint(i, leg.hip), knee = c.key_has_joint(i, leg.knee),
               ankle = c.key_has_joint(i, leg.ankle);
    if (hip || knee || ankle) (*fixed)[f] = 1;
    if (hip && knee && ankle && c.key_fixes_root(i)) (*known)[f] = 1;
  }
  for (const EffectorTarget& e : c.effectors) {
    for (int j = e.joint; j >= 0; j = skel.parents[j]) {
      if (j == leg.ankle || j == leg.knee || j == leg.hip) (*fixed)[e.frame] = 1;
    }
    for (int j = leg.ankle; j >= 0; j = skel.parents[j]) {
      if (j == e.joint) (*fixed)[e.frame] = 1;  // an effector on the root or the spine above the hip
    }
  }
}

// Where the ankle is held at frame f of the contact [s, e]: the known ankle
// positions inside the contact (`inside`, sorted), interpolated between them
// and held beyond the first and the last, else the contact's mean position.
Eigen::Vector3d lock_point(const GlobalPose& pose, int ankle, const std::vector<int>& inside,
                           const Eigen::Vector3d& mean, int f) {
  if (inside.empty()) return mean;
  if (f <= inside.front()) return pose.position(inside.front(), ankle);
  if (f >= inside.back()) return pose.position(inside.back(), ankle);
  const auto it = std::lower_bound(inside.begin(), inside.end(), f);
  const int b = *it, a = *(it - 1);
  const double t = static_cast<double>(f - a) / (b - a);
  return pose.position(a, ankle) * (1.0 - t) + pose.position(b, ankle) * t;
}

// Per frame, where the ankle is held (`goal`) and how much (`weight`): 1
// inside each contact [s, e] of two or more frames, on each side a ramp over
// `ramp` frames whose weight grows with the square of the distance covered
// ((k / (ramp + 1))^2 at the k-th frame); where ramps of two contacts meet,
// the larger weight. A linear ramp moved a swinging foot a quarter of its
// distance to the lock point on its first frame: 0.27 m at once for a foot
// 34 cm from the contact's mean three frames before it (the Blender add-on's
// test); the squared weights start small and still hold the foot near the
// contact (docs/BENCHMARKS.md, "Foot locking"). A `fixed` frame (one the lock
// must not touch) within a ramp shortens it to start there from zero, so the
// first free frame next to a key is not moved most of the way at once.
void contact_goals(const GlobalPose& pose, int ankle, const std::vector<char>& on, const std::vector<char>& known,
                   const std::vector<char>& fixed, int ramp, std::vector<Eigen::Vector3d>* goal,
                   std::vector<double>* weight) {
  const int N = static_cast<int>(on.size());
  goal->assign(N, Eigen::Vector3d::Zero());
  weight->assign(N, 0.0);
  for (int s = 0; s < N;) {
    if (!on[s]) {
      ++s;
      continue;
    }
    int e = s;
    while (e + 1 < N && on[e + 1]) ++e;
    if (e > s) {
      std::vector<int> inside;
      for (int f = s; f <= e; ++f) {
        if (known[f]) inside.push_back(f);
      }
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (int f = s; f <= e; ++f) mean += pose.position(f, ankle);
      mean /= (e - s + 1);
      // The ramps run from weight 0 at `before` and `after` to 1 at s and e.
      int before = s - ramp - 1, after = e + ramp + 1;
      for (int f = std::max(0, s - ramp); f < s; ++f) {
        if (fixed[f]) before = f;
      }
      for (int f = std::min(N - 1, e + ramp); f > e; --f) {
        if (fixed[f]) after = f;
      }
      for (int f = std::max(0, before + 1); f <= std::min(N - 1, after - 1); ++f) {
        const double t = f < s ? static_cast<double>(f - before) / (s - before)
                               : f > e ? static_cast<double>(after - f) / (after - e) : 1.0;
        const double w = t * t;
        if (w > (*weight)[f]) {
          (*weight)[f] = w;
          (*goal)[f] = lock_point(pose, ankle, inside, mean, std::clamp(f, s, e));
        }
      }
    }
    s = e + 1;
  }
}

// Moves the chain's end toward `goal` with `weight` at every frame not `fixed`:
// its ground position (x, z) only, or its height too.
// Where hold() moves the ankle at a frame: `weight` of the way from `now` to
// `goal` (on the ground plane only unless `height`).
Eigen::Vector3d hold_target(const Eigen::Vector3d& now, const Eigen::Vector3d& goal, double weight, bool height) {
  Eigen::Vector3d target = now + weight * (goal - now);
  if (!height) target.y() = now.y();
  return target;
}

void hold(const Leg& leg, const std::vector<Eigen::Vector3d>& goal, const std::vector<double>& weight,
          const std::vector<char>& fixed, bool height, Motion* out, GlobalPose* pose) {
  for (int f = 0; f < out->num_frames(); ++f) {
    if (weight[f] <= 0.0 || fixed[f]) continue;
    two_bone_ik(out, pose, f, leg.hip, leg.knee, leg.ankle,
                hold_target(pose->position(f, leg.ankle), goal[f], weight[f], height));
  }
}

// A pin's target can lie beyond the leg's reach from the hip (the solve left
// the hip a little too far from the planted point, the leg straight); the IK
// would stop short and the foot slide. On frames where the root is free, the
// root moves toward the target by the shortfall, so that the IK reaches it
// (hold() with height). The shortfall is zero where the target is in reach, so
// the root path stays continuous.
void bring_in_reach(const MotionConstraints& c, const Leg& leg, const std::vector<Eigen::Vector3d>& goal,
                    const std::vector<double>& weight, const std::vector<char>& fixed, Motion* out,
                    GlobalPose* pose) {
  const int J = out->num_joints();
  for (int f = 0; f < out->num_frames(); ++f) {
    if (weight[f] <= 0.0 || fixed[f] || c.fixes_root_position(f)) continue;
    const Eigen::Vector3d hip = pose->position(f, leg.hip);
    // two_bone_ik() clamps a target to 1e-4 inside the reach: aim 2e-4 inside.
    const double reach = (pose->position(f, leg.knee) - hip).norm() +
                         (pose->position(f, leg.ankle) - pose->position(f, leg.knee)).norm() - 2e-4;
    const Eigen::Vector3d to_goal =
        hold_target(pose->position(f, leg.ankle), goal[f], weight[f], /*height=*/true) - hip;
    const double shortfall = to_goal.norm() - reach;
    if (!(shortfall > 0)) continue;
    const Eigen::Vector3d delta = shortfall * to_goal.normalized();
    out->root_positions[f] += delta;
    for (int j = 0; j < J; ++j) pose->positions[static_cast<size_t>(f) * J + j] += delta;
  }
}

// The warnings of a pin that cannot hold exactly: keys inside it that place
// the joint at different points, and frames a key or a target protects.
void warn_conflicts(const std::string& what, const GlobalPose& pose, int joint, const ContactPin& p,
                    const std::vector<char>& fixed, const std::vector<char>& known, std::vector<std::string>* out) {
  int first_known = -1;
  std::string moved, partial;
  for (int f = p.first; f <= p.last; ++f) {
    if (known[f]) {
      if (first_known < 0) first_known = f;
      const double cm = (pose.position(f, joint) - pose.position(first_known, joint)).norm() * 100.0;
      if (cm > 0.5) {
        char buf[96];
        std::snprintf(buf, sizeof buf, "%s%d (%.1f cm from frame %d)", moved.empty() ? "" : ", ", f, cm, first_known);
        moved += buf;
      }
    } else if (fixed[f]) {
      partial += (partial.empty() ? "" : ", ") + std::to_string(f);
    }
  }
  if (!moved.empty())
    out->push_back(what + ": keys inside it place the joint at different points, so it moves between them: frame " +
                   moved);
  if (!partial.empty())
    out->push_back(what + ": keys or end-effector targets constrain its chain at frame(s) " + partial +
                   ", which keep their values there");
}

}  // namespace

void lock_feet(const RigInfo& rig, const MotionConstraints& c, const std::vector<float>& contacts, int ramp,
               Motion* out) {
  const int N = out->num_frames(), F = rig.num_feet();
  const Skeleton& skel = out->skeleton;
  auto in_contact = [&](int k, const GlobalPose& pose) {
    // The predictor says so and the output's joint is low enough.
    const double low = rig.foot_heights[k] + rig.foot_thresholds[k];
    std::vector<char> on(N);
    for (int f = 0; f < N; ++f)
      on[f] = contacts[static_cast<size_t>(f) * F + k] > 0.5f && pose.position(f, rig.foot_joints[k]).y() < low;
    return on;
  };
  std::vector<std::vector<double>> ankle_weight(skel.num_joints());
  for (int k = 0; k < F; ++k) {
    Leg leg;
    if (!leg_above(skel, rig.foot_joints[k], &leg)) continue;
    std::vector<char> fixed, known;
    protected_frames(c, skel, leg, N, &fixed, &known);
    GlobalPose pose = forward_kinematics(*out);
    std::vector<Eigen::Vector3d> goal;
    contact_goals(pose, leg.ankle, in_contact(k, pose), known, fixed, ramp, &goal, &ankle_weight[leg.ankle]);
    hold(leg, goal, ankle_weight[leg.ankle], fixed, /*height=*/false, out, &pose);
  }
  for (int k = 0; k < F; ++k) {
    const int toe = rig.foot_joints[k];
    Leg leg;
    if (skel.parents[toe] <= 0 || leg_above(skel, toe, &leg) || !leg_above(skel, skel.parents[toe], &leg)) continue;
    std::vector<char> fixed, known;
    protected_frames(c, skel, leg, N, &fixed, &known);
    for (size_t i = 0; i < c.keys.size(); ++i) {
      if (c.key_has_joint(i, toe)) fixed[c.keys[i].frame] = 1;
    }
    GlobalPose pose = forward_kinematics(*out);
    std::vector<Eigen::Vector3d> goal;
    std::vector<double> weight;
    contact_goals(pose, toe, in_contact(k, pose), known, fixed, ramp, &goal, &weight);
    const std::vector<double>& planted = ankle_weight[leg.ankle];
    for (int f = 0; f < N; ++f) {
      if (weight[f] <= 0.0 || fixed[f]) continue;
      const Eigen::Vector3d t = pose.position(f, toe);
      Eigen::Vector3d step = weight[f] * (goal[f] - t);
      step.y() = 0.0;
      // A planted heel stays where it is and the foot turns about it; a lifted
      // heel follows the toe, the foot keeping its orientation.
      const double w_heel = planted.empty() ? 0.0 : planted[f];
      const Eigen::Vector3d a0 = pose.position(f, leg.ankle);
      two_bone_ik(out, &pose, f, leg.hip, leg.knee, leg.ankle, a0 + (1.0 - w_heel) * step);
      const Eigen::Vector3d a = pose.position(f, leg.ankle);
      const Eigen::Vector3d from = t + (a - a0) - a, to = t + step - a;
      if (from.norm() < 1e-6 || to.norm() < 1e-6) continue;
      const Eigen::Quaterniond turn = Eigen::Quaterniond::FromTwoVectors(from, to);
      const int J = out->num_joints();
      Eigen::Quaterniond& ankle_global = pose.rotations[static_cast<size_t>(f) * J + leg.ankle];
      ankle_global = (turn * ankle_global).normalized();
      out->rotation(f, leg.ankle) = (pose.rotation(f, leg.knee).conjugate() * ankle_global).normalized();
    }
  }
}

std::vector<std::string> pin_contacts(const MotionConstraints& c, int ramp, Motion* out) {
  std::vector<std::string> warnings;
  const Skeleton& skel = out->skeleton;
  const int N = out->num_frames();
  struct Pinned {
    Leg leg;
    std::vector<char> fixed;
    std::vector<Eigen::Vector3d> goal;
    std::vector<double> weight;
  };
  std::vector<Pinned> pinned;
  // Every root move comes before every hold: a root move carries the whole
  // body, so after a hold it would shift the feet already pinned.
  GlobalPose pose = forward_kinematics(*out);
  for (const ContactPin& p : c.contacts) {
    const std::string what = "contact of joint '" + skel.names[p.joint] + "' on frames " + std::to_string(p.first) +
                             ".." + std::to_string(p.last);
    Pinned pin;
    pin.leg.ankle = p.joint;
    pin.leg.knee = skel.parents[p.joint];
    pin.leg.hip = pin.leg.knee > 0 ? skel.parents[pin.leg.knee] : -1;
    if (pin.leg.hip <= 0) {
      warnings.push_back(what + " is not held: the joint needs two bones above it below the root");
      continue;
    }
    std::vector<char> known;
    protected_frames(c, skel, pin.leg, N, &pin.fixed, &known);
    std::vector<char> on(N, 0);
    std::fill(on.begin() + p.first, on.begin() + p.last + 1, 1);
    contact_goals(pose, pin.leg.ankle, on, known, pin.fixed, ramp, &pin.goal, &pin.weight);
    warn_conflicts(what, pose, pin.leg.ankle, p, pin.fixed, known, &warnings);
    bring_in_reach(c, pin.leg, pin.goal, pin.weight, pin.fixed, out, &pose);
    pinned.push_back(std::move(pin));
  }
  // A later pin's root move can take an earlier pin's target out of reach again.
  for (const Pinned& pin : pinned) bring_in_reach(c, pin.leg, pin.goal, pin.weight, pin.fixed, out, &pose);
  for (const Pinned& pin : pinned) {
    pose = forward_kinematics(*out);
    hold(pin.leg, pin.goal, pin.weight, pin.fixed, /*height=*/true, out, &pose);
  }
  return warnings;
}

}  // namespace mf
