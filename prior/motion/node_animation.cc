#include "prior/motion/node_animation.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"

namespace mf {
namespace {

// A world transform without its scale: position and rotation.
struct Pose {
  Eigen::Vector3d position;
  Eigen::Quaterniond rotation;
};

// Checks a track's sizes, times and values; `property` and `node` name it in
// messages ("the rotation keys of node 'Hips' ...").
void check_track(const KeyTrack& t, const std::string& property, const std::string& node) {
  const std::string what = "the " + property + " keys of node '" + node + "'";
  const size_t groups = t.interpolation == KeyInterpolation::CubicSpline ? 3 : 1;
  if (t.values.size() != t.times.size() * groups * static_cast<size_t>(t.width))
    throw InputError(what + " have " + std::to_string(t.values.size()) + " numbers for " +
                     std::to_string(t.times.size()) + " key times");
  for (size_t k = 0; k < t.times.size(); ++k) {
    if (!std::isfinite(t.times[k])) throw InputError(what + " have a non-finite time (NaN or infinity)");
    if (k > 0 && !(t.times[k] > t.times[k - 1]))
      throw InputError(what + " have times that do not increase (" + std::to_string(t.times[k - 1]) + " then " +
                       std::to_string(t.times[k]) + " s)");
  }
  for (double v : t.values)
    if (!std::isfinite(v)) throw InputError(what + " hold a non-finite number (NaN or infinity)");
}

// The value of key k (its middle group for cubic splines).
Eigen::VectorXd key_value(const KeyTrack& t, size_t k, int group = 1) {
  const size_t groups = t.interpolation == KeyInterpolation::CubicSpline ? 3 : 1;
  const size_t at = (k * groups + (groups == 3 ? group : 0)) * static_cast<size_t>(t.width);
  return Eigen::Map<const Eigen::VectorXd>(t.values.data() + at, t.width);
}

// The track at time `time` (clamped to its keys).
Eigen::VectorXd sample_track(const KeyTrack& t, double time) {
  const auto next = std::upper_bound(t.times.begin(), t.times.end(), time);
  size_t k = next == t.times.begin() ? 0 : static_cast<size_t>(next - t.times.begin()) - 1;
  if (next == t.times.end() || std::abs(time - t.times[k]) <= 1e-6) return key_value(t, k);
  if (next == t.times.begin() || std::abs(*next - time) <= 1e-6) return key_value(t, k + (next != t.times.begin()));
  if (t.interpolation == KeyInterpolation::Step) return key_value(t, k);
  const double dt = t.times[k + 1] - t.times[k], u = (time - t.times[k]) / dt;
  if (t.interpolation == KeyInterpolation::CubicSpline) {
    const double u2 = u * u, u3 = u2 * u;
    return (2 * u3 - 3 * u2 + 1) * key_value(t, k) + dt * (u3 - 2 * u2 + u) * key_value(t, k, 2) +
           (-2 * u3 + 3 * u2) * key_value(t, k + 1) + dt * (u3 - u2) * key_value(t, k + 1, 0);
  }
  const Eigen::VectorXd a = key_value(t, k), b = key_value(t, k + 1);
  if (t.width != 4) return (1 - u) * a + u * b;
  const Eigen::Quaterniond q = slerp(Eigen::Quaterniond(a[3], a[0], a[1], a[2]).normalized(),
                                     Eigen::Quaterniond(b[3], b[0], b[1], b[2]).normalized(), u);
  return Eigen::Vector4d(q.x(), q.y(), q.z(), q.w());
}

// The frames of an animation: first key, rate, count.
struct Frames {
  double start = 0, fps = 30;
  int count = 0;
};

Frames frames_of(const NodeAnimation& a, const SceneReadOptions& options) {
  std::vector<double> times;
  for (size_t i = 0; i < a.tracks.size(); ++i) {
    const NodeTracks& tr = a.tracks[i];
    for (const auto& [t, property] : {std::pair{&tr.translation, "translation"}, std::pair{&tr.rotation, "rotation"},
                                      std::pair{&tr.scale, "scale"}}) {
      check_track(*t, property, a.names[i]);
      times.insert(times.end(), t->times.begin(), t->times.end());
    }
  }
  if (times.empty()) throw InputError("no animation: no node has keys");
  std::sort(times.begin(), times.end());
  Frames fr;
  fr.start = times.front();
  if (options.fps != 0 && !(std::isfinite(options.fps) && options.fps > 0 && options.fps <= 1000))
    throw InputError("the frame rate to sample at must be between 0 and 1000 fps, not " + std::to_string(options.fps));
  fr.fps = options.fps > 0 ? options.fps : fps_from_key_times(times);
  const double count = std::floor((times.back() - fr.start) * fr.fps + 1e-3) + 1;
  if (!(count <= static_cast<double>(kMaxSceneFrames)))
    throw InputError("the animation lasts " + std::to_string(times.back() - fr.start) + " s: over " +
                     std::to_string(kMaxSceneFrames) + " frames at " + std::to_string(fr.fps) + " fps");
  fr.count = static_cast<int>(count);
  return fr;
}

// The local transform of node i at time `time`.
NodeTransform local_at(const NodeAnimation& a, int i, double time) {
  NodeTransform t = a.rest[i];
  const NodeTracks& tr = a.tracks[i];
  if (!tr.translation.empty()) t.translation = sample_track(tr.translation, time).head<3>();
  if (!tr.scale.empty()) t.scale = sample_track(tr.scale, time).head<3>();
  if (!tr.rotation.empty()) {
    const Eigen::VectorXd q = sample_track(tr.rotation, time);
    t.rotation = Eigen::Quaterniond(q[3], q[0], q[1], q[2]);
  }
  return t;
}

// The joints, their parents among the joints, and the nodes the conversion
// needs (joints and their ancestors).
struct Armature {
  std::vector<int> joint_parent;  // per node: nearest joint above it, -1 for none
  std::vector<char> needed;
  int top = -1;
};

Armature find_armature(const NodeAnimation& a) {
  const int n = static_cast<int>(a.names.size());
  Armature arm;
  arm.joint_parent.assign(n, -1);
  arm.needed.assign(n, 0);
  std::vector<int> nearest(n, -1);  // the node itself if a joint, else the nearest joint above
  int joints = 0;
  for (int i = 0; i < n; ++i) {
    const int p = a.parents[i];
    if (p >= i) throw InputError("the node '" + a.names[i] + "' comes before its parent (a cycle?)");
    const int above = p < 0 ? -1 : nearest[p];
    nearest[i] = a.joints[i] ? i : above;
    if (!a.joints[i]) continue;
    ++joints;
    arm.joint_parent[i] = above;
    if (above >= 0) continue;
    if (arm.top >= 0)
      throw InputError("the armature has two roots: '" + a.names[arm.top] + "' and '" + a.names[i] +
                       "' (one skeleton per file is read)");
    arm.top = i;
  }
  if (joints == 0) throw InputError("no armature: no joints were found");
  if (joints > kMaxSceneJoints)
    throw InputError("the armature has " + std::to_string(joints) + " joints; at most " +
                     std::to_string(kMaxSceneJoints) + " are read");
  for (int i = n - 1; i >= 0; --i) {
    if (a.joints[i]) arm.needed[i] = 1;
    if (arm.needed[i] && a.parents[i] >= 0) arm.needed[a.parents[i]] = 1;
  }
  return arm;
}

Eigen::Affine3d checked_affine(const NodeTransform& t, const std::string& name) {
  if (!t.translation.allFinite() || !t.rotation.coeffs().allFinite() || !t.scale.allFinite())
    throw InputError("the node '" + name + "' has a non-finite transform (NaN or infinite keys)");
  if (t.rotation.norm() < 1e-6) throw InputError("the node '" + name + "' has a zero rotation quaternion");
  return to_affine(t);
}

// World poses of the needed nodes for one set of local transforms.
template <class Local>
std::vector<Pose> world_poses(const NodeAnimation& a, const Armature& arm, Local local) {
  const size_t n = a.names.size();
  std::vector<Eigen::Affine3d> world(n);
  std::vector<Pose> poses(n);
  Eigen::Affine3d top = Eigen::Affine3d::Identity();
  top.linear() = a.to_y_up * a.metres_per_unit;
  for (size_t i = 0; i < n; ++i) {
    if (!arm.needed[i]) continue;
    const Eigen::Affine3d parent = a.parents[i] < 0 ? top : world[a.parents[i]];
    world[i] = parent * checked_affine(local(static_cast<int>(i)), a.names[i]);
    Eigen::Matrix3d r = world[i].linear();
    for (int k = 0; k < 3; ++k) {
      const double norm = r.col(k).norm();
      if (!(norm > 1e-12)) throw InputError("the node '" + a.names[i] + "' is scaled to zero");
      r.col(k) /= norm;
    }
    poses[i].position = world[i].translation();
    poses[i].rotation = Eigen::Quaterniond(r).normalized();
  }
  return poses;
}

// The root of the motion: the top joint, moved down single-child chains while
// a joint below moves against its parent (the container rule, see the header).
int motion_root(const NodeAnimation& a, const Armature& arm, const Frames& fr, const std::vector<Pose>& rest) {
  const size_t n = a.names.size();
  std::vector<char> moving(n, 0);
  for (int f = 0; f < fr.count; ++f) {
    const double time = fr.start + f / fr.fps;
    const std::vector<Pose> pose = world_poses(a, arm, [&](int i) { return local_at(a, i, time); });
    for (size_t i = 0; i < n; ++i) {
      const int p = arm.joint_parent[i];
      if (!a.joints[i] || p < 0 || moving[i]) continue;
      const Eigen::Vector3d rest_offset = rest[i].position - rest[p].position;
      const Eigen::Quaterniond delta = pose[p].rotation * rest[p].rotation.conjugate();
      const Eigen::Vector3d offset = delta.conjugate() * (pose[i].position - pose[p].position);
      moving[i] = (offset - rest_offset).norm() > 1e-5 + 1e-4 * rest_offset.norm();
    }
  }
  // below[i]: a joint at or below i moves.
  std::vector<char> below(moving);
  for (size_t i = n; i-- > 0;)
    if (below[i] && arm.joint_parent[i] >= 0) below[arm.joint_parent[i]] = 1;
  int root = arm.top;
  for (;;) {
    int child = -1, count = 0;
    for (size_t i = 0; i < n; ++i)
      if (a.joints[i] && arm.joint_parent[i] == root) child = static_cast<int>(i), ++count;
    if (count != 1 || !below[child]) return root;
    root = child;
  }
}

// The joints of the subtree of `root` in depth-first order (children in node order).
std::vector<int> joint_order(const NodeAnimation& a, const Armature& arm, int root) {
  std::vector<int> order;
  std::vector<int> stack{root};
  while (!stack.empty()) {
    const int j = stack.back();
    stack.pop_back();
    order.push_back(j);
    for (int i = static_cast<int>(a.names.size()) - 1; i > j; --i)
      if (a.joints[i] && arm.joint_parent[i] == j) stack.push_back(i);
  }
  return order;
}

void check_counts(const Frames& fr, size_t joints) {
  if (static_cast<long long>(joints) * fr.count > kMaxSceneJointFrames)
    throw InputError("the animation has " + std::to_string(fr.count) + " frames of " + std::to_string(joints) +
                     " joints; at most " + std::to_string(kMaxSceneJointFrames) + " joint-frames are read");
}

}  // namespace

Motion motion_from_node_animation(const NodeAnimation& a, const SceneReadOptions& options) {
  const size_t n = a.names.size();
  if (a.parents.size() != n || a.joints.size() != n || a.rest.size() != n || a.tracks.size() != n)
    throw std::logic_error("motion_from_node_animation: the node arrays differ in size");
  const Armature arm = find_armature(a);
  const Frames fr = frames_of(a, options);
  check_counts(fr, std::count(a.joints.begin(), a.joints.end(), 1));
  const std::vector<Pose> rest = world_poses(a, arm, [&](int i) { return a.rest[i]; });
  const int root = motion_root(a, arm, fr, rest);
  const std::vector<int> order = joint_order(a, arm, root);

  Motion m;
  m.fps = fr.fps;
  std::vector<int> index(n, -1);
  for (size_t k = 0; k < order.size(); ++k) {
    const int j = order[k];
    index[j] = static_cast<int>(k);
    const int p = k == 0 ? -1 : arm.joint_parent[j];
    m.skeleton.names.push_back(a.names[j]);
    m.skeleton.parents.push_back(p < 0 ? -1 : index[p]);
    m.skeleton.offsets.push_back(p < 0 ? rest[j].position : Eigen::Vector3d(rest[j].position - rest[p].position));
  }
  m.skeleton.validate();
  const size_t J = order.size();
  m.rotations.resize(J * static_cast<size_t>(fr.count));
  m.root_positions.resize(static_cast<size_t>(fr.count));
  std::vector<Eigen::Quaterniond> delta(J);
  for (int f = 0; f < fr.count; ++f) {
    const double time = fr.start + f / fr.fps;
    const std::vector<Pose> pose = world_poses(a, arm, [&](int i) { return local_at(a, i, time); });
    m.root_positions[f] = pose[root].position;
    for (size_t k = 0; k < J; ++k) {
      const int j = order[k];
      delta[k] = pose[j].rotation * rest[j].rotation.conjugate();
      Eigen::Quaterniond q = k == 0 ? delta[k] : delta[m.skeleton.parents[k]].conjugate() * delta[k];
      q.normalize();
      const double agreement = f == 0 ? q.w() : q.coeffs().dot(m.rotation(f - 1, static_cast<int>(k)).coeffs());
      if (agreement < 0) q.coeffs() = -q.coeffs();
      m.rotation(f, static_cast<int>(k)) = q;
    }
  }
  m.validate();
  return m;
}

Eigen::Affine3d to_affine(const NodeTransform& t) {
  Eigen::Affine3d m = Eigen::Affine3d::Identity();
  m.translate(t.translation);
  m.rotate(t.rotation.normalized());
  m.scale(t.scale);
  return m;
}

NodeTransform transform_from_affine(const Eigen::Affine3d& matrix) {
  NodeTransform t;
  t.translation = matrix.translation();
  Eigen::Matrix3d r = matrix.linear();
  for (int k = 0; k < 3; ++k) {
    t.scale[k] = r.col(k).norm();
    if (t.scale[k] > 0) r.col(k) /= t.scale[k];
  }
  if (r.determinant() < 0) r.col(0) = -r.col(0), t.scale[0] = -t.scale[0];
  t.rotation = Eigen::Quaterniond(r);
  return t;
}

std::vector<char> mark_joints(const std::vector<int>& parents, const std::vector<char>& animated) {
  const size_t n = parents.size();
  std::vector<char> above(n, 0), below(n, 0), joints(animated);
  for (size_t i = 0; i < n; ++i)
    if (parents[i] >= 0) above[i] = above[parents[i]] || animated[parents[i]];
  for (size_t i = n; i-- > 0;)
    if (parents[i] >= 0 && (below[i] || animated[i])) below[parents[i]] = 1;
  for (size_t i = 0; i < n; ++i)
    if (above[i] && below[i]) joints[i] = 1;
  return joints;
}

int pick_animation(const std::vector<std::string>& names, const SceneReadOptions& options) {
  if (names.empty()) throw InputError("no animation: the file has none");
  if (options.animation.empty()) {
    if (options.animation_index < 0 || options.animation_index >= static_cast<int>(names.size()))
      throw InputError("there is no animation " + std::to_string(options.animation_index) + ": the file has " +
                       std::to_string(names.size()) + " (0 to " + std::to_string(names.size() - 1) + ")");
    return options.animation_index;
  }
  std::string listed;
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i] == options.animation) return static_cast<int>(i);
    listed += (i ? ", '" : "'") + names[i] + "'";
  }
  throw InputError("there is no animation named '" + options.animation + "': the file has " + listed);
}

double fps_from_key_times(const std::vector<double>& times) {
  double smallest = 0;
  for (size_t i = 1; i < times.size(); ++i) {
    const double d = times[i] - times[i - 1];
    if (d > 1e-7 && (smallest == 0 || d < smallest)) smallest = d;
  }
  if (smallest == 0) return 30.0;
  const double fps = 1.0 / smallest;
  if (fps > 1000.0)
    throw InputError("the keys are " + std::to_string(smallest) +
                     " s apart (over 1000 fps): give the frame rate to sample at");
  const double rounded = std::round(fps);
  return rounded > 0 && std::abs(fps - rounded) <= 1e-3 * fps ? rounded : fps;
}

}  // namespace mf
