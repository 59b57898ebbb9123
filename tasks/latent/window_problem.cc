#include "tasks/latent/window_problem.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <string>

#include "prior/motion/errors.h"
#include "prior/runtime/kinematics.h"

namespace mf {
namespace {

Eigen::Matrix3d rot_y(double yaw) { return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix(); }

// World -> canonical of the problem's transform.
struct Unturn {
  explicit Unturn(const GroundTransform& t) : rotation(rot_y(-t.yaw)), origin(t.x, 0.0, t.z) {}
  Eigen::Vector3d point(const Eigen::Vector3d& world) const { return rotation * (world - origin); }
  Eigen::Matrix3d rotation;
  Eigen::Vector3d origin;
};

// Throws unless the window fits the motion, its keys lie inside it and
// `anchor` is a key that fixes the root.
void check_window(const RigInfo& rig, const Motion& motion, int begin, int length, const MotionConstraints& c,
                  int anchor) {
  check_model_skeleton(rig, motion.skeleton, "motion");
  if (begin < 0 || length < 2 || begin + length > motion.num_frames())
    throw InputError("window [" + std::to_string(begin) + ", " + std::to_string(begin + length) +
                     ") does not fit the motion (at least 2 frames)");
  int anchor_key = -1;
  for (size_t k = 0; k < c.keys.size(); ++k) {
    const int f = c.keys[k].frame;
    if (f < 0 || f >= length) throw InputError("a key lies outside its window");
    if (f == anchor && c.key_fixes_root(k)) anchor_key = static_cast<int>(k);
  }
  if (anchor_key < 0) throw InputError("the window's anchor frame must be a key that fixes the root");
}

// The pose keys' targets in the canonical frame; the root-relative key
// positions are the FK of the target rotations.
void set_key_targets(const RigInfo& rig, const Motion& motion, int begin, const MotionConstraints& c,
                     RuntimeWindowProblem* p) {
  const Skeleton& s = rig.skeleton;
  const int J = s.num_joints(), K = static_cast<int>(c.keys.size());
  const Unturn unturn(p->transform);
  p->key_frames.resize(K);
  p->key_rotations.resize(K, J * 9);
  for (int k = 0; k < K; ++k)
    for (int j = 0; j < J; ++j) Eigen::Map<Eigen::Matrix<float, 3, 3, Eigen::RowMajor>>(&p->key_rotations(k, j * 9)).setIdentity();
  p->key_rotation_mask.setZero(K, J);
  p->key_position_mask.setZero(K, J);
  p->key_root.setZero(K, 3);
  p->key_root_mask.setZero(K);
  std::vector<char> chain(J);
  for (int k = 0; k < K; ++k) {
    const PoseKey& key = c.keys[k];
    const int f = begin + key.frame;
    p->key_frames[k] = key.frame;
    for (int j = 0; j < J; ++j) {
      const bool on = c.key_has_joint(k, j);
      chain[j] = on && (j == 0 || chain[s.parents[j]]);
      if (j > 0 && chain[j]) p->key_position_mask(k, j) = 1.0f;
      if (!on) continue;
      p->key_rotation_mask(k, j) = 1.0f;
      Eigen::Matrix3d m = motion.rotation(f, j).normalized().toRotationMatrix();
      if (j == 0) m = unturn.rotation * m;
      Eigen::Map<Eigen::Matrix<float, 3, 3, Eigen::RowMajor>>(&p->key_rotations(k, j * 9)) = m.cast<float>();
    }
    if (key.root_position) {
      p->key_root.row(k) = unturn.point(motion.root_positions[f]).cast<float>().transpose();
      p->key_root_mask[k] = 1.0f;
    }
  }
  runtime::MatrixRXf globals;
  runtime::Kinematics(s).forward(p->key_rotations, runtime::MatrixRXf::Zero(K, 3), &p->key_positions, &globals);
}

// The end-effector targets in the canonical frame.
void set_effector_targets(int J, int length, const MotionConstraints& c, RuntimeWindowProblem* p) {
  const Unturn unturn(p->transform);
  const int E = static_cast<int>(c.effectors.size());
  p->effector_frames.resize(E);
  p->effector_joints.resize(E);
  p->effector_targets.resize(E, 3);
  p->effector_weights.resize(E);
  for (int e = 0; e < E; ++e) {
    const EffectorTarget& t = c.effectors[e];
    if (t.frame < 0 || t.frame >= length) throw InputError("an end-effector target lies outside its window");
    if (t.joint < 0 || t.joint >= J) throw InputError("end-effector joint out of range");
    p->effector_frames[e] = t.frame;
    p->effector_joints[e] = t.joint;
    p->effector_targets.row(e) = unturn.point(t.position).cast<float>().transpose();
    p->effector_weights[e] = static_cast<float>(t.weight);
  }
}

// The contact pins as pairs of consecutive pinned frames (flat frame * J +
// joint indices into the window's [T, J] positions).
void set_contact_pins(int J, int length, const MotionConstraints& c, RuntimeWindowProblem* p) {
  p->pin_from.clear();
  p->pin_to.clear();
  for (const ContactPin& pin : c.contacts) {
    if (pin.joint < 0 || pin.joint >= J) throw InputError("contact joint out of range");
    for (int f = std::max(pin.first, 0) + 1; f <= std::min(pin.last, length - 1); ++f) {
      p->pin_from.push_back((f - 1) * J + pin.joint);
      p->pin_to.push_back(f * J + pin.joint);
    }
  }
}

// The trajectory rows the solver follows, in the canonical frame.
void set_trajectory_targets(int length, const MotionConstraints& c, RuntimeWindowProblem* p) {
  const std::vector<TrajectoryPoint> rows = c.followed_trajectory();
  const Unturn unturn(p->transform);
  const int R = static_cast<int>(rows.size());
  p->trajectory_frames.resize(R);
  p->trajectory_ground.resize(R, 2);
  p->trajectory_forward.resize(R, 2);
  for (int r = 0; r < R; ++r) {
    const TrajectoryPoint& t = rows[r];
    if (t.frame < 0 || t.frame >= length) throw InputError("a trajectory row lies outside its window");
    p->trajectory_frames[r] = t.frame;
    const Eigen::Vector3d x = unturn.point(Eigen::Vector3d(t.x, 0.0, t.z));
    const Eigen::Vector3d f = (unturn.rotation * Eigen::Vector3d(t.forward_x, 0.0, t.forward_z)).normalized();
    p->trajectory_ground.row(r) << static_cast<float>(x.x()), static_cast<float>(x.z());
    p->trajectory_forward.row(r) << static_cast<float>(f.x()), static_cast<float>(f.z());
  }
}

}  // namespace

RuntimeWindowProblem make_runtime_problem(const RigInfo& rig, const Motion& motion, int begin, int length,
                                          const MotionConstraints& constraints, int anchor) {
  check_window(rig, motion, begin, length, constraints, anchor);
  RuntimeWindowProblem p;
  p.length = length;
  p.anchor = anchor;
  p.transform = canonical_transform(motion, begin + anchor, rig);
  set_key_targets(rig, motion, begin, constraints, &p);
  set_effector_targets(rig.num_joints(), length, constraints, &p);
  set_contact_pins(rig.num_joints(), length, constraints, &p);
  set_trajectory_targets(length, constraints, &p);
  return p;
}

}  // namespace mf
