#include "prior/rig/retarget.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <nlohmann/json.hpp>

#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "prior/util/strict_json.h"

namespace mf {
namespace {

using Eigen::Quaterniond;
using Eigen::Vector3d;

Vector3d unit(const Vector3d& v) {
  const double n = v.norm();
  return n > 1e-12 ? Vector3d(v / n) : Vector3d::Zero();
}

// What defines one joint's anatomical frame: its first axis runs from `from`
// to `to`; its second is one of the directions below, measured per frame.
enum class Second { HipLateral, ArmLateral, TorsoLateral, Up, Knee, Elbow };

struct Rule {
  int from = -1, to = -1;
  Second second = Second::HipLateral;
  int side = 0;
  /// A forearm without a hand joint (ArmParts::hand_is_end): `to` is `from`
  /// and the first axis is the joint's own rest offset, the forearm continuing
  /// the upper arm in the rest pose.
  bool along_offset = false;
};

// The rule of every part joint; toe_rules: the feet measured along the toes.
std::vector<Rule> part_rules(const RigParts& p, int joints, bool along_toes) {
  std::vector<Rule> r(joints);
  auto set = [&](int j, int from, int to, Second s, int side = 0) {
    if (j >= 0 && from >= 0 && to >= 0) r[j] = {from, to, s, side};
  };
  set(p.hips, p.hips, p.chest, Second::HipLateral);
  for (int s : p.spine) set(s, s, p.chest, Second::TorsoLateral);
  set(p.chest, p.chest, p.head, Second::ArmLateral);
  set(p.neck, p.neck, p.head, Second::ArmLateral);
  set(p.head, p.chest, p.head, Second::ArmLateral);
  for (int s = 0; s < 2; ++s) {
    const ArmParts& a = p.arms[s];
    set(a.shoulder, a.shoulder, a.upper, Second::Up);
    set(a.upper, a.upper, a.fore, Second::Elbow, s);
    set(a.fore, a.fore, a.hand, Second::Elbow, s);
    if (a.hand < 0 && a.hand_is_end && a.fore >= 0) r[a.fore] = {a.fore, a.fore, Second::Elbow, s, true};
    set(a.hand, a.fore, a.hand, Second::Elbow, s);
    const LegParts& l = p.legs[s];
    set(l.thigh, l.thigh, l.shin, Second::Knee, s);
    set(l.shin, l.shin, l.foot, Second::Knee, s);
    if (along_toes && l.toe >= 0) set(l.foot, l.foot, l.toe, Second::Knee, s);
    else set(l.foot, l.shin, l.foot, Second::Knee, s);
    set(l.toe, l.foot, l.toe, Second::Knee, s);
  }
  return r;
}

// Joints that play no part but sit between a part joint above and one below
// (extra spine or neck joints, twist bones, clavicles the map leaves out) take
// their first axis toward the part below and the second of the part above.
void add_between_rules(const Skeleton& s, const RigParts& p, std::vector<Rule>* rules) {
  const int J = s.num_joints();
  std::vector<bool> is_part(J, false);
  for (const auto& [name, j] : p.list()) is_part[j] = true;
  const auto kids = s.children();
  for (int j = 0; j < J; ++j) {
    if (is_part[j]) continue;
    int above = s.parents[j];
    while (above >= 0 && !is_part[above]) above = s.parents[above];
    if (above < 0 || (*rules)[above].from < 0) continue;
    // nearest part joint below (breadth first)
    int below = -1;
    std::vector<int> queue = kids[j];
    for (size_t q = 0; q < queue.size() && below < 0; ++q) {
      if (is_part[queue[q]]) below = queue[q];
      else queue.insert(queue.end(), kids[queue[q]].begin(), kids[queue[q]].end());
    }
    if (below < 0) continue;
    Rule r = (*rules)[above];
    r.from = j, r.to = below;
    (*rules)[j] = r;
  }
}

// Rest-pose position of every joint (identity rotations, root at the origin).
std::vector<Vector3d> rest_positions(const Skeleton& s) {
  std::vector<Vector3d> p(s.num_joints(), Vector3d::Zero());
  for (int j = 1; j < s.num_joints(); ++j) p[j] = p[s.parents[j]] + s.offsets[j];
  return p;
}

struct Pose {
  const GlobalPose& g;
  int f;
  const Skeleton& s;
  Vector3d p(int j) const { return g.position(f, j); }
  // The wrist: the hand joint's position, or for an arm without one the
  // forearm's end along its rest offset (ArmParts::hand_is_end).
  Vector3d wrist(const ArmParts& a) const {
    return a.hand >= 0 ? p(a.hand) : p(a.fore) + g.rotation(f, a.fore) * s.offsets[a.fore];
  }
};

Vector3d second_axis(const Rule& r, const RigParts& parts, const Pose& pose) {
  const Vector3d hip_lat = unit(pose.p(parts.legs[0].thigh) - pose.p(parts.legs[1].thigh));
  const Vector3d arm_lat = unit(pose.p(parts.arms[0].upper) - pose.p(parts.arms[1].upper));
  switch (r.second) {
    case Second::HipLateral: return hip_lat;
    case Second::ArmLateral: return arm_lat;
    case Second::TorsoLateral: return hip_lat + arm_lat;
    case Second::Up: return unit(pose.p(parts.head) - pose.p(parts.chest));
    case Second::Knee: {
      const LegParts& l = parts.legs[r.side];
      const Vector3d a = unit(pose.p(l.shin) - pose.p(l.thigh)), b = unit(pose.p(l.foot) - pose.p(l.shin));
      return a.cross(b) + 0.02 * hip_lat;  // knees bend backwards: the hinge points left; the small term decides a straight leg
    }
    case Second::Elbow: {
      const ArmParts& a = parts.arms[r.side];
      const Vector3d u = unit(pose.p(a.fore) - pose.p(a.upper)), v = unit(pose.wrist(a) - pose.p(a.fore));
      return u.cross(v) - 0.02 * arm_lat;  // elbows bend forwards: the hinge points right
    }
  }
  return Vector3d::Zero();
}

// A rotation whose x axis is `first` and whose z axis is `second` made
// orthogonal to it (any perpendicular when `second` is degenerate).
Quaterniond frame_from(Vector3d first, Vector3d second) {
  first = unit(first);
  if (first.isZero()) first = Vector3d::UnitX();
  Vector3d z = second - second.dot(first) * first;
  if (z.norm() < 1e-9 * std::max(1.0, second.norm())) {
    Eigen::Index k;
    first.cwiseAbs().minCoeff(&k);
    Vector3d e = Vector3d::Zero();
    e[k] = 1;
    z = e - e.dot(first) * first;
  }
  z.normalize();
  Eigen::Matrix3d m;
  m.col(0) = first;
  m.col(1) = z.cross(first);
  m.col(2) = z;
  return Quaterniond(m).normalized();
}

// The body's directions in a rest pose recognised as a T or A pose.
struct RestBody {
  std::vector<Vector3d> p;  // rest positions
  std::vector<Vector3d> offsets;
  Vector3d up, left, forward;
};

bool near(const Vector3d& a, const Vector3d& b, double max_degrees) {
  return a.dot(b) >= std::cos(max_degrees * M_PI / 180.0);
}

std::optional<RestBody> recognise_rest_pose(const Skeleton& s, const RigParts& parts) {
  if (!parts.missing().empty()) return std::nullopt;
  RestBody b;
  b.p = rest_positions(s);
  b.offsets = s.offsets;
  const auto dir = [&](int from, int to) { return unit(b.p[to] - b.p[from]); };
  // Rest poses stand along an axis of the file: that axis is up (the line from
  // the hips to the head leans with the spine's curve).
  const Vector3d torso = dir(parts.hips, parts.head);
  Eigen::Index k;
  torso.cwiseAbs().maxCoeff(&k);
  b.up = Vector3d::Zero();
  b.up[k] = torso[k] < 0 ? -1.0 : 1.0;
  const Vector3d across = dir(parts.legs[1].thigh, parts.legs[0].thigh);
  if (!near(torso, b.up, 30) || across.isZero() || std::abs(across.dot(b.up)) > 0.25) return std::nullopt;
  b.left = unit(across - across.dot(b.up) * b.up);
  b.forward = b.left.cross(b.up);
  if (!near(dir(parts.hips, parts.chest), b.up, 30) || !near(dir(parts.chest, parts.head), b.up, 30)) return std::nullopt;
  for (int side = 0; side < 2; ++side) {
    const LegParts& l = parts.legs[side];
    if (!near(dir(l.thigh, l.foot), -b.up, 25)) return std::nullopt;
    if (l.toe >= 0 && dir(l.foot, l.toe).dot(b.forward) < 0.3) return std::nullopt;
    const ArmParts& a = parts.arms[side];
    const Vector3d upper = dir(a.upper, a.fore), fore = a.hand >= 0 ? dir(a.fore, a.hand) : upper;
    const Vector3d out = side == 0 ? b.left : Vector3d(-b.left);
    // Straight arms out to the side, between 60 degrees below horizontal and 20 above.
    if (!near(upper, fore, 30) || !near(upper, out, 65) || std::abs(upper.dot(b.forward)) > 0.5 ||
        upper.dot(b.up) < -std::sin(60 * M_PI / 180) || upper.dot(b.up) > std::sin(20 * M_PI / 180))
      return std::nullopt;
  }
  return b;
}

// The anatomical frame (in world = local axes at rest) of a joint with rule
// `r` in a recognised rest pose: the conventions of reference_pose().
Quaterniond rest_frame(const Rule& r, const RestBody& b) {
  switch (r.second) {
    case Second::HipLateral:
    case Second::TorsoLateral:
    case Second::ArmLateral: return frame_from(b.up, b.left);
    case Second::Up: return frame_from(b.p[r.to] - b.p[r.from], b.up);
    case Second::Knee: return frame_from(b.p[r.to] - b.p[r.from], b.left);
    case Second::Elbow: {
      const Vector3d first = unit(r.along_offset ? b.offsets[r.from] : Vector3d(b.p[r.to] - b.p[r.from]));
      return frame_from(first, first.cross(b.forward));
    }
  }
  return Quaterniond::Identity();
}

std::vector<Quaterniond> estimate_frames(const Motion& motion, const GlobalPose& g, const RigParts& parts,
                                         const std::vector<int>& frames, bool along_toes) {
  const int J = motion.num_joints();
  std::vector<Rule> rules = part_rules(parts, J, along_toes);
  add_between_rules(motion.skeleton, parts, &rules);
  std::vector<Vector3d> first(J, Vector3d::Zero()), second(J, Vector3d::Zero());
  for (int f : frames) {
    const Pose pose{g, f, motion.skeleton};
    for (int j = 0; j < J; ++j) {
      const Rule& r = rules[j];
      if (r.from < 0) continue;
      const Quaterniond inv = g.rotation(f, j).conjugate();
      first[j] += r.along_offset ? unit(motion.skeleton.offsets[r.from]) : Vector3d(inv * unit(pose.p(r.to) - pose.p(r.from)));
      second[j] += inv * second_axis(r, parts, pose);
    }
  }
  std::vector<Quaterniond> out(J, Quaterniond::Identity());
  for (int j = 0; j < J; ++j)
    if (rules[j].from >= 0) out[j] = frame_from(first[j], second[j]);
  return out;
}

Quaterniond json_quat(const nlohmann::json& v, const std::string& what) {
  if (!v.is_array() || v.size() != 4) throw InputError(what + " must be an array of 4 numbers (w, x, y, z)");
  Quaterniond q;
  for (int i = 0; i < 4; ++i)
    if (!v[i].is_number()) throw InputError(what + " must be an array of 4 numbers (w, x, y, z)");
  q = Quaterniond(v[0].get<double>(), v[1].get<double>(), v[2].get<double>(), v[3].get<double>());
  if (!q.coeffs().allFinite() || q.norm() < 1e-6) throw InputError(what + " is not a rotation");
  return q.normalized();
}

nlohmann::json quat_json(const Quaterniond& q) { return {q.w(), q.x(), q.y(), q.z()}; }

// Destination joints between two corresponding ones (corr >= 0): the nearest
// such joint above and below, and the arc-length fraction between them.
struct Between {
  int above = -1, below = -1;
  double s = 0;
};

std::vector<Between> between_joints(const Skeleton& D, const std::vector<int>& corr) {
  const int JD = D.num_joints();
  std::vector<Between> between(JD);
  const auto kids = D.children();
  for (int j = 0; j < JD; ++j) {
    if (corr[j] >= 0) continue;
    int above = D.parents[j];
    double up = D.offsets[j].norm();
    while (above >= 0 && corr[above] < 0) up += D.offsets[above].norm(), above = D.parents[above];
    if (above < 0) continue;
    int below = -1;
    double down = 0;
    std::vector<std::pair<int, double>> queue;  // breadth first, with the arc length so far
    for (int c : kids[j]) queue.emplace_back(c, D.offsets[c].norm());
    for (size_t q = 0; q < queue.size() && below < 0; ++q) {
      if (corr[queue[q].first] >= 0) below = queue[q].first, down = queue[q].second;
      else
        for (int c : kids[queue[q].first]) queue.emplace_back(c, queue[q].second + D.offsets[c].norm());
    }
    if (below >= 0) between[j] = {above, below, up + down > 1e-12 ? up / (up + down) : 0.5};
  }
  return between;
}

// The root translation of frame f of `out` (local rotations set) that puts
// joint `hips` at `target`; the root's own translation is the reference's
// (zero without one) when the hips are not the root.
Vector3d root_placing_hips(const Motion& out, int f, int hips, const Vector3d& target, const Motion* reference) {
  if (hips == 0) return target;
  const Skeleton& D = out.skeleton;
  const Vector3d root = reference ? reference->root_positions[f] : Vector3d(0, 0, 0);
  std::vector<int> chain;
  for (int j = hips; j > 0; j = D.parents[j]) chain.push_back(j);
  Vector3d pos = root;
  Quaterniond rot = out.rotation(f, 0);
  for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
    pos += rot * D.offsets[*it];
    rot = rot * out.rotation(f, *it);
  }
  return root + (target - pos);
}

// Rotation vector (axis times angle, the shortest way) of q, and back.
Vector3d log_map(Quaterniond q) {
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const Eigen::AngleAxisd aa(q.normalized());
  return aa.angle() * aa.axis();
}

Quaterniond exp_map(const Vector3d& r) {
  const double angle = r.norm();
  return angle < 1e-12 ? Quaterniond::Identity() : Quaterniond(Eigen::AngleAxisd(angle, r / angle));
}

}  // namespace

void measure_locked_axes(const Motion& motion, double max_sd_degrees, RigAnatomy* anatomy) {
  const int J = motion.num_joints(), F = motion.num_frames();
  if (static_cast<int>(anatomy->mean_local.size()) != J)
    throw InputError("measure_locked_axes: the anatomy's mean rotations do not match the motion's joints");
  const double limit = max_sd_degrees * M_PI / 180.0;
  anatomy->locked_axes.assign(J, {});
  if (F < 2) return;
  for (int j = 0; j < J; ++j) {
    const Quaterniond inv_mean = anatomy->mean_local[j].conjugate();
    Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
    Vector3d sum = Vector3d::Zero();
    for (int f = 0; f < F; ++f) {
      const Vector3d r = log_map(inv_mean * motion.rotation(f, j));
      sum += r;
      second += r * r.transpose();
    }
    const Vector3d mean = sum / F;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(second / F - mean * mean.transpose());
    std::vector<Vector3d> locked;
    for (int k = 0; k < 3; ++k)
      if (std::sqrt(std::max(0.0, eig.eigenvalues()[k])) < limit) locked.push_back(eig.eigenvectors().col(k));
    if (locked.size() < 3) anatomy->locked_axes[j] = std::move(locked);
  }
}

Quaterniond without_locked_rotation(const RigAnatomy& anatomy, int joint, const Quaterniond& local) {
  if (joint >= static_cast<int>(anatomy.locked_axes.size()) || anatomy.locked_axes[joint].empty()) return local;
  const Quaterniond& mean = anatomy.mean_local[joint];
  Vector3d r = log_map(mean.conjugate() * local);
  for (const Vector3d& a : anatomy.locked_axes[joint]) r -= r.dot(a) * a;
  return (mean * exp_map(r)).normalized();
}

double leg_length(const Skeleton& s, const RigParts& p) {
  const std::vector<Vector3d> rest = rest_positions(s);
  double sum = 0;
  int n = 0;
  for (const LegParts& l : p.legs) {
    if (l.thigh < 0 || l.shin < 0 || l.foot < 0) continue;
    sum += (rest[l.shin] - rest[l.thigh]).norm() + (rest[l.foot] - rest[l.shin]).norm();
    ++n;
  }
  return n ? sum / n : 0.0;
}

bool rest_pose_is_t_or_a(const Skeleton& s, const RigParts& parts) { return recognise_rest_pose(s, parts).has_value(); }

std::array<double, 2> mean_elbow_bend(const Motion& motion, const RigParts& parts, const std::vector<int>& frames) {
  std::array<double, 2> bend{0.0, 0.0};
  std::vector<int> listed = frames;
  if (listed.empty())
    for (int f = 0; f < motion.num_frames(); ++f) listed.push_back(f);
  if (listed.empty()) return bend;
  Motion poses = Motion::identity(motion.skeleton, static_cast<int>(listed.size()), motion.fps);
  for (size_t i = 0; i < listed.size(); ++i) {
    if (listed[i] < 0 || listed[i] >= motion.num_frames()) throw InputError("mean_elbow_bend: frame out of range");
    poses.root_positions[i] = motion.root_positions[listed[i]];
    for (int j = 0; j < motion.num_joints(); ++j) poses.rotation(static_cast<int>(i), j) = motion.rotation(listed[i], j);
  }
  const GlobalPose g = forward_kinematics(poses);
  for (int s = 0; s < 2; ++s) {
    const ArmParts& a = parts.arms[s];
    if (a.upper < 0 || a.fore < 0 || (a.hand < 0 && !a.hand_is_end)) continue;
    for (int f = 0; f < poses.num_frames(); ++f) {
      const Pose pose{g, f, motion.skeleton};
      const Vector3d u = unit(pose.p(a.fore) - pose.p(a.upper));
      const Vector3d v = unit(pose.wrist(a) - pose.p(a.fore));
      bend[s] += u.cross(v).norm();
    }
    bend[s] /= poses.num_frames();
  }
  return bend;
}

bool take_rest_pose_frames(const Skeleton& s, const RigParts& parts, RigAnatomy* anatomy,
                           std::array<bool, 2> keep_elbow_frames) {
  const int J = s.num_joints();
  if (static_cast<int>(anatomy->frames.size()) != J || static_cast<int>(anatomy->toe_frames.size()) != J)
    throw InputError("take_rest_pose_frames: the anatomy does not match the skeleton's joints");
  const std::optional<RestBody> body = recognise_rest_pose(s, parts);
  if (!body) return false;
  for (bool toes : {false, true}) {
    std::vector<Rule> rules = part_rules(parts, J, toes);
    add_between_rules(s, parts, &rules);
    for (int j = 0; j < J; ++j) {
      const Rule& r = rules[j];
      if (r.from < 0) continue;
      if (r.second == Second::Elbow && keep_elbow_frames[r.side]) continue;
      (toes ? anatomy->toe_frames : anatomy->frames)[j] = rest_frame(r, *body);
    }
  }
  return true;
}

RigAnatomy user_rig_anatomy(const Motion& motion, const RigParts& parts, const std::vector<int>& frames) {
  RigAnatomy anatomy = estimate_anatomy(motion, parts, frames);
  constexpr double kMinBend = 0.15;  // mean sine of the elbow's bend: about 9 degrees
  const std::array<double, 2> bend = mean_elbow_bend(motion, parts, frames);
  RigAnatomy rest = anatomy;
  take_rest_pose_frames(motion.skeleton, parts, &rest, {false, false});
  std::array<bool, 2> keep{};
  for (int s = 0; s < 2; ++s) {
    const int fore = parts.arms[s].fore;
    keep[s] = bend[s] >= kMinBend &&
              (fore < 0 || geodesic_angle(anatomy.frames[fore], rest.frames[fore]) > kElbowConventionDegrees * M_PI / 180);
  }
  take_rest_pose_frames(motion.skeleton, parts, &anatomy, keep);
  return anatomy;
}

RigAnatomy estimate_anatomy(const Motion& motion, const RigParts& parts, const std::vector<int>& frames_in) {
  const std::vector<std::string> missing = parts.missing();
  if (!missing.empty()) throw InputError("cannot measure the rig's anatomy: no " + missing.front());
  std::vector<int> frames = frames_in;
  if (frames.empty())
    for (int f = 0; f < motion.num_frames(); ++f) frames.push_back(f);
  if (frames.empty()) throw InputError("cannot measure the rig's anatomy of a motion without frames");
  for (int f : frames)
    if (f < 0 || f >= motion.num_frames()) throw InputError("estimate_anatomy: frame " + std::to_string(f) + " is out of range");
  // Only the listed frames are read (the others may be unknown).
  Motion listed = Motion::identity(motion.skeleton, static_cast<int>(frames.size()), motion.fps);
  for (size_t i = 0; i < frames.size(); ++i) {
    listed.root_positions[i] = motion.root_positions[frames[i]];
    for (int j = 0; j < motion.num_joints(); ++j) listed.rotation(static_cast<int>(i), j) = motion.rotation(frames[i], j);
  }
  std::vector<int> all(frames.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  const GlobalPose g = forward_kinematics(listed);
  RigAnatomy a;
  a.frames = estimate_frames(listed, g, parts, all, false);
  a.toe_frames = estimate_frames(listed, g, parts, all, true);
  const int J = motion.num_joints();
  a.mean_local.assign(J, Quaterniond::Identity());
  for (int j = 0; j < J; ++j) {
    Eigen::Vector4d sum = Eigen::Vector4d::Zero();
    const Quaterniond first = listed.rotation(0, j).normalized();
    for (int f : all) {
      Quaterniond q = listed.rotation(f, j).normalized();
      if (q.dot(first) < 0) q.coeffs() = -q.coeffs();
      sum += q.coeffs();
    }
    if (sum.norm() > 1e-12) a.mean_local[j] = Quaterniond(sum.normalized());
  }
  a.leg_length = leg_length(motion.skeleton, parts);
  return a;
}

std::string RigAnatomy::to_json(const Skeleton& s) const {
  nlohmann::ordered_json j;
  j["format"] = "motionfield-rig-anatomy";
  j["version"] = 1;
  j["leg_length"] = leg_length;
  nlohmann::ordered_json joints = nlohmann::ordered_json::object();
  for (int i = 0; i < s.num_joints(); ++i) {
    joints[s.names[i]] = {{"frame", quat_json(frames[i])}, {"toe_frame", quat_json(toe_frames[i])},
                          {"mean_local", quat_json(mean_local[i])}};
    if (i < static_cast<int>(locked_axes.size()) && !locked_axes[i].empty()) {
      nlohmann::ordered_json axes = nlohmann::ordered_json::array();
      for (const Vector3d& a : locked_axes[i]) axes.push_back({a.x(), a.y(), a.z()});
      joints[s.names[i]]["locked_axes"] = axes;
    }
  }
  j["joints"] = joints;
  return j.dump(1);
}

RigAnatomy RigAnatomy::from_json(const std::string& text, const Skeleton& s, const std::string& source) {
  nlohmann::json j = parse_json_strict(text, source);
  if (!j.is_object() || j.value("format", "") != "motionfield-rig-anatomy" || !j.contains("joints") ||
      !j["joints"].is_object() || !j.contains("leg_length") || !j["leg_length"].is_number())
    throw InputError(source + ": not a motionfield rig anatomy file");
  RigAnatomy a;
  a.leg_length = j["leg_length"].get<double>();
  if (!(std::isfinite(a.leg_length) && a.leg_length > 0)) throw InputError(source + ": leg_length must be positive");
  for (const std::string& name : s.names) {
    if (!j["joints"].contains(name)) throw InputError(source + ": no entry for joint '" + name + "'");
    const nlohmann::json& e = j["joints"][name];
    if (!e.is_object() || !e.contains("frame") || !e.contains("toe_frame") || !e.contains("mean_local"))
      throw InputError(source + ": joint '" + name + "' needs frame, toe_frame and mean_local");
    a.frames.push_back(json_quat(e["frame"], source + ": " + name + ".frame"));
    a.toe_frames.push_back(json_quat(e["toe_frame"], source + ": " + name + ".toe_frame"));
    a.mean_local.push_back(json_quat(e["mean_local"], source + ": " + name + ".mean_local"));
    std::vector<Vector3d> axes;
    if (e.contains("locked_axes")) {
      const nlohmann::json& l = e["locked_axes"];
      const std::string what = source + ": " + name + ".locked_axes";
      if (!l.is_array() || l.size() > 2) throw InputError(what + " must be an array of at most 2 directions");
      for (const nlohmann::json& v : l) {
        if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number())
          throw InputError(what + ": each direction must be an array of 3 numbers");
        const Vector3d d(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
        if (!d.allFinite() || d.norm() < 1e-6) throw InputError(what + ": a direction is not a finite nonzero vector");
        axes.push_back(d.normalized());
      }
    }
    a.locked_axes.push_back(std::move(axes));
  }
  return a;
}

std::vector<Quaterniond> reference_pose(const Skeleton& s, const RigParts& p, const RigAnatomy& a,
                                        double arm_down_degrees) {
  const int J = s.num_joints();
  std::vector<Quaterniond> world(J, Quaterniond::Identity());
  std::vector<bool> set(J, false);
  // Canonical world frames (first axis, second axis) of each part's anatomy.
  auto put = [&](int j, const Vector3d& first, const Vector3d& second, bool toe_frame = false) {
    if (j < 0) return;
    world[j] = frame_from(first, second) * (toe_frame ? a.toe_frames[j] : a.frames[j]).conjugate();
    set[j] = true;
  };
  const Vector3d X = Vector3d::UnitX(), Y = Vector3d::UnitY(), Z = Vector3d::UnitZ();
  put(p.hips, Y, X);
  for (int j : p.spine) put(j, Y, X);
  put(p.chest, Y, X);
  put(p.neck, Y, X);
  put(p.head, Y, X);
  const double down = arm_down_degrees * M_PI / 180.0;
  for (int side = 0; side < 2; ++side) {
    const double sx = side == 0 ? 1.0 : -1.0;  // the character's left is +X
    const ArmParts& arm = p.arms[side];
    put(arm.shoulder, sx * X, Y);
    const Vector3d dir = sx * std::cos(down) * X - std::sin(down) * Y;
    const Vector3d hinge = dir.cross(Z);
    put(arm.upper, dir, hinge);
    put(arm.fore, dir, hinge);
    put(arm.hand, dir, hinge);
    const LegParts& leg = p.legs[side];
    put(leg.thigh, -Y, X);
    put(leg.shin, -Y, X);
    if (leg.toe >= 0) put(leg.foot, Z, X, true);
    else put(leg.foot, -Y, X);
    put(leg.toe, Z, X);
  }
  for (int j = 0; j < J; ++j)
    if (!set[j]) world[j] = (j == 0 ? Quaterniond::Identity() : world[s.parents[j]]) * a.mean_local[j];
  return world;
}

Retargeter::Retargeter(Skeleton user, Skeleton model, RigMap map, RigAnatomy user_anatomy, RigAnatomy model_anatomy)
    : user_(std::move(user)),
      model_(std::move(model)),
      map_(std::move(map)),
      user_anatomy_(std::move(user_anatomy)),
      model_anatomy_(std::move(model_anatomy)) {
  if (map_.user_of_model.size() != static_cast<size_t>(model_.num_joints()) ||
      user_anatomy_.frames.size() != static_cast<size_t>(user_.num_joints()) ||
      model_anatomy_.frames.size() != static_cast<size_t>(model_.num_joints()))
    throw InputError("retargeter: the map or an anatomy does not match its skeleton");
  toes_ = true;
  for (int s = 0; s < 2; ++s)
    toes_ = toes_ && map_.model_parts.legs[s].toe >= 0 && map_.user_of_model[map_.model_parts.legs[s].toe] >= 0;
  const double user_leg = leg_length(user_, map_.user_parts), model_leg = leg_length(model_, map_.model_parts);
  if (!(user_leg > 1e-6 && model_leg > 1e-6)) throw InputError("retargeter: a rig has legs of zero length");
  scale_ = model_leg / user_leg;
}

std::vector<int> Retargeter::source_joints(bool to_model) const {
  std::vector<int> corr((to_model ? model_ : user_).num_joints(), -1);
  for (int m = 0; m < model_.num_joints(); ++m) {
    const int u = map_.user_of_model[m];
    if (u < 0) continue;
    if (to_model) corr[m] = u;
    else corr[u] = m;
  }
  return corr;
}

const Quaterniond& Retargeter::joint_frame(const RigAnatomy& anatomy, const RigParts& parts, int j) const {
  const bool foot = j == parts.legs[0].foot || j == parts.legs[1].foot;
  return toes_ && foot ? anatomy.toe_frames[j] : anatomy.frames[j];
}

Motion Retargeter::transfer(const Motion& src, bool to_model, const Motion* reference) const {
  const Skeleton& D = to_model ? model_ : user_;
  const RigAnatomy& AS = to_model ? user_anatomy_ : model_anatomy_;
  const RigAnatomy& AD = to_model ? model_anatomy_ : user_anatomy_;
  const RigParts& PS = to_model ? map_.user_parts : map_.model_parts;
  const RigParts& PD = to_model ? map_.model_parts : map_.user_parts;
  const int JD = D.num_joints(), F = src.num_frames();
  const std::vector<int> corr = source_joints(to_model);
  const std::vector<Between> between = between_joints(D, corr);

  const GlobalPose g = forward_kinematics(src);
  Motion out = Motion::identity(D, F, src.fps);
  std::vector<Quaterniond> world(JD), target(JD);
  std::vector<bool> has_target(JD);
  const int hips_src = to_model ? map_.user_parts.hips : map_.model_parts.hips;
  const int hips_dst = PD.hips;
  const double scale = to_model ? scale_ : 1.0 / scale_;
  for (int f = 0; f < F; ++f) {
    // World targets of corresponding joints, then of the joints between them.
    for (int j = 0; j < JD; ++j) {
      has_target[j] = corr[j] >= 0;
      if (has_target[j])
        target[j] = g.rotation(f, corr[j]) * joint_frame(AS, PS, corr[j]) * joint_frame(AD, PD, j).conjugate();
    }
    for (int j = 0; j < JD; ++j) {
      const Between& b = between[j];
      if (b.above < 0) continue;
      const Quaterniond fa = target[b.above] * joint_frame(AD, PD, b.above);
      const Quaterniond fb = target[b.below] * joint_frame(AD, PD, b.below);
      target[j] = slerp(fa, fb, b.s) * AD.frames[j].conjugate();
      has_target[j] = true;
    }
    // Local rotations top-down; joints without a target keep the reference's
    // (user side) or their mean (model side).
    for (int j = 0; j < JD; ++j) {
      const int p = D.parents[j];
      Quaterniond local;
      if (has_target[j]) {
        local = p < 0 ? target[j] : world[p].conjugate() * target[j];
      } else {
        local = reference ? reference->rotation(f, j) : AD.mean_local[j];
      }
      local.normalize();
      // The model never saw its locked axes turn (a knee off its hinge): keep
      // the motion off them; the children keep their world targets.
      if (to_model && has_target[j]) local = without_locked_rotation(AD, j, local);
      out.rotation(f, j) = local;
      world[j] = p < 0 ? local : (world[p] * local).normalized();
    }
    // Root: the hips land where the source's hips are, scaled.
    const Vector3d hips_target = g.position(f, hips_src) * scale;
    out.root_positions[f] = root_placing_hips(out, f, hips_dst, hips_target, reference);
  }
  return out;
}

Motion Retargeter::to_model(const Motion& user) const {
  if (!user.skeleton.same_as(user_)) throw InputError("retargeter: the motion is not on the user's rig");
  return transfer(user, true, nullptr);
}

Motion Retargeter::to_user(const Motion& model, const Motion& reference) const {
  if (!reference.skeleton.same_as(user_)) throw InputError("retargeter: the reference is not on the user's rig");
  if (reference.num_frames() != model.num_frames())
    throw InputError("retargeter: the reference has " + std::to_string(reference.num_frames()) +
                     " frames, the motion " + std::to_string(model.num_frames()));
  const Motion raw = transfer(model, false, &reference);
  const Motion raw_ref = transfer(to_model(reference), false, &reference);
  Motion out = raw;
  const int J = user_.num_joints();
  for (int f = 0; f < out.num_frames(); ++f) {
    for (int j = 0; j < J; ++j) {
      Quaterniond q = (reference.rotation(f, j).normalized() * raw_ref.rotation(f, j).conjugate() * raw.rotation(f, j))
                          .normalized();
      if (f > 0 && q.dot(out.rotation(f - 1, j)) < 0) q.coeffs() = -q.coeffs();
      out.rotation(f, j) = q;
    }
    out.root_positions[f] = raw.root_positions[f] + (reference.root_positions[f] - raw_ref.root_positions[f]);
  }
  return out;
}

}  // namespace mf
