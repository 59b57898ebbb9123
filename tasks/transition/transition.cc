#include "tasks/transition/transition.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "prior/motion/errors.h"
#include "prior/motion/interpolation.h"

namespace mf {
namespace {

// Yaw (radians about +Y) of the twist of `q` about the vertical; 0 when it has
// none (a half turn about a horizontal axis).
double twist_yaw(const Eigen::Quaterniond& q) {
  if (std::abs(q.w()) + std::abs(q.y()) < 1e-12) return 0.0;
  return 2.0 * std::atan2(q.y(), q.w());
}

// The turn about +Y that takes B's root orientation at frame j to A's at frame i.
Eigen::Quaterniond facing_turn(const Motion& a, int i, const Motion& b, int j) {
  const Eigen::Quaterniond r = a.rotation(i, 0).normalized() * b.rotation(j, 0).normalized().conjugate();
  return Eigen::Quaterniond(Eigen::AngleAxisd(twist_yaw(r), Eigen::Vector3d::UnitY()));
}

Eigen::Vector3d on_ground(const Eigen::Vector3d& p) { return {p.x(), 0.0, p.z()}; }

// The mean ground velocity (per frame step) of the root from frame `first` to `last`.
Eigen::Vector3d ground_velocity(const Motion& m, int first, int last) {
  if (last <= first) return Eigen::Vector3d::Zero();
  return on_ground(m.root_positions[last] - m.root_positions[first]) / (last - first);
}

Eigen::Vector3d end_velocity(const Motion& a, int i) {
  return ground_velocity(a, std::max(0, i - kTransitionVelocityFrames), i);
}
Eigen::Vector3d start_velocity(const Motion& b, int j) {
  return ground_velocity(b, j, std::min(b.num_frames() - 1, j + kTransitionVelocityFrames));
}

// Joint positions of frame `f` with the root at the origin, the root turned by `turn`.
std::vector<Eigen::Vector3d> pose_at_origin(const Motion& m, int f, const Eigen::Quaterniond& turn) {
  Motion one = m.slice(f, f + 1);
  one.root_positions[0].setZero();
  one.rotation(0, 0) = turn * one.rotation(0, 0).normalized();
  return forward_kinematics(one).positions;
}

// "clip B's rig differs from A's: ..." for the first difference of two
// skeletons that cannot be matched (neither by name nor by hierarchy).
[[noreturn]] void rig_mismatch(const Skeleton& a, const Skeleton& b) {
  const std::string lead = "clip B's rig differs from A's: ";
  if (a.num_joints() != b.num_joints())
    throw InputError(lead + "A has " + std::to_string(a.num_joints()) + " joints, B has " +
                     std::to_string(b.num_joints()));
  auto parent_name = [](const Skeleton& s, int j) { return s.parents[j] < 0 ? std::string("none") : s.names[s.parents[j]]; };
  for (int j = 0; j < a.num_joints(); ++j) {
    const int k = b.find(a.names[j]);
    if (k < 0) continue;
    if (parent_name(a, j) != parent_name(b, k))
      throw InputError(lead + "joint '" + a.names[j] + "' has the parent '" + parent_name(a, j) + "' in A and '" +
                       parent_name(b, k) + "' in B");
  }
  int missing = -1, differs = -1;
  for (int j = a.num_joints() - 1; j >= 0; --j) {
    if (b.find(a.names[j]) < 0) missing = j;
    if (a.parents[j] != b.parents[j]) differs = j;
  }
  if (missing >= 0 && differs >= 0)
    throw InputError(lead + "A's joint '" + a.names[missing] + "' is not in B, and the hierarchies differ at joint " +
                     std::to_string(differs) + " ('" + a.names[differs] + "' under '" + parent_name(a, differs) +
                     "' in A, '" + b.names[differs] + "' under '" + parent_name(b, differs) + "' in B)");
  throw InputError(lead + "the joints have other names and other parents");  // not reached for valid skeletons
}

// B's joint for each of A's joints: by name, else by index on the same
// hierarchy (*by_index set); rig_mismatch() otherwise.
std::vector<int> joint_map(const Skeleton& a, const Skeleton& b, bool* by_index) {
  const int n = a.num_joints();
  *by_index = false;
  if (n != b.num_joints()) rig_mismatch(a, b);
  std::vector<int> from(static_cast<size_t>(n));
  bool names = true;
  for (int j = 0; j < n && names; ++j) names = (from[j] = b.find(a.names[j])) >= 0;
  if (names) {
    for (int j = 0; j < n; ++j)
      if (b.parents[from[j]] != (a.parents[j] < 0 ? -1 : from[a.parents[j]])) rig_mismatch(a, b);
    return from;
  }
  if (a.parents != b.parents) rig_mismatch(a, b);
  *by_index = true;
  for (int j = 0; j < n; ++j) from[j] = j;
  return from;
}

// A frame index as given (negative: from the end) checked against [lo, hi].
int resolve_frame(int frame, int frames, int lo, int hi, const char* key, const char* clip, const char* keeps) {
  const int f = frame < 0 ? frames + frame : frame;
  if (f < lo || f > hi)
    throw InputError(std::string(key) + " " + std::to_string(frame) + " is out of range: clip " + clip + " has " +
                     std::to_string(frames) + " frames and " + keeps + " (" + std::to_string(lo) + ".." +
                     std::to_string(hi) + ", or negative from the end)");
  return f;
}

void check_clip(const Motion& m, const char* clip) {
  if (m.num_frames() < 2)
    throw InputError(std::string("clip ") + clip + " has " + std::to_string(m.num_frames()) +
                     " frame(s): a transition needs at least 2 in each clip");
  m.validate();
}

// B on A's rig and rate, with the warnings of the way there.
Motion clip_b_for(const Motion& a, const Motion& b, std::vector<std::string>* warnings) {
  Motion out = transition_onto_rig_of(a, b, warnings);
  if (same_frame_rate(b.fps, a.fps)) {
    out.fps = a.fps;
    return out;
  }
  out = run_resample(out, a.fps, "cubic", warnings);
  std::ostringstream msg;
  msg << "clip B is at " << b.fps << " fps and A at " << a.fps << " fps: B was resampled to " << a.fps
      << " fps (cubic spline) before the transition";
  warnings->push_back(msg.str());
  if (out.num_frames() < 2)
    throw InputError("clip B has fewer than 2 frames at A's frame rate: a transition needs at least 2 in each clip");
  return out;
}

int checked_frames(const TransitionRequest& r) {
  if (r.frames < 0 || r.frames > kMaxTransitionFrames)
    throw InputError("the transition's frames must be between 1 and " + std::to_string(kMaxTransitionFrames) +
                     " (0 = automatic), not " + std::to_string(r.frames));
  return r.frames;
}

// A[0..i], `frames` frames holding A's pose at i, B[j..].
Motion joined_clip(const Motion& a, int i, const Motion& b, int j, int frames) {
  Motion out = a.slice(0, i + 1);
  const Motion hold = a.slice(i, i + 1);
  for (int f = 0; f < frames; ++f) {
    out.rotations.insert(out.rotations.end(), hold.rotations.begin(), hold.rotations.end());
    out.root_positions.push_back(hold.root_positions[0]);
  }
  out.rotations.insert(out.rotations.end(), b.rotations.begin() + static_cast<long>(j) * b.num_joints(), b.rotations.end());
  out.root_positions.insert(out.root_positions.end(), b.root_positions.begin() + j, b.root_positions.end());
  return out;
}

// The caller's constraints plus whole-pose keys on every frame outside the transition.
MotionConstraints transition_constraints(const TransitionRequest& r, const Skeleton& skeleton, int first, int frames,
                                         int total) {
  ConstraintSpec spec = r.constraints;
  std::vector<int> known;
  for (int f = 0; f < total; ++f)
    if (f < first || f >= first + frames) known.push_back(f);
  spec.add_whole_pose_keys(known);
  return spec.resolve(skeleton, r.length_scale);
}

}  // namespace

Motion transition_onto_rig_of(const Motion& a, const Motion& b, std::vector<std::string>* warnings) {
  bool by_index = false;
  const std::vector<int> from = joint_map(a.skeleton, b.skeleton, &by_index);
  if (by_index && warnings)
    warnings->push_back("clip B's joints have other names than A's ('" + b.skeleton.names[0] + "' for '" +
                        a.skeleton.names[0] + "', ...) on the same hierarchy: they were taken as A's in order");
  Motion out;
  out.skeleton = a.skeleton;
  out.fps = b.fps;
  out.root_positions = b.root_positions;
  const int n = a.num_joints();
  out.rotations.resize(b.rotations.size());
  for (int f = 0; f < b.num_frames(); ++f)
    for (int j = 0; j < n; ++j) out.rotation(f, j) = b.rotation(f, from[j]);
  return out;
}

Motion place_transition_clip(const Motion& a, const Motion& b, int from_frame, int to_frame, int frames) {
  const Eigen::Quaterniond turn = facing_turn(a, from_frame, b, to_frame);
  const Eigen::Vector3d velocity = (end_velocity(a, from_frame) + turn * start_velocity(b, to_frame)) / 2.0;
  const Eigen::Vector3d target = on_ground(a.root_positions[from_frame]) + (frames + 1) * velocity;
  const Eigen::Vector3d pivot = on_ground(b.root_positions[to_frame]);
  Motion out = b;
  for (int f = 0; f < out.num_frames(); ++f) {
    out.rotation(f, 0) = turn * b.rotation(f, 0);
    out.root_positions[f] = turn * (b.root_positions[f] - pivot) + target;
  }
  return out;
}

int automatic_transition_frames(const Motion& a, const Motion& b, int from_frame, int to_frame, bool ground) {
  const std::vector<Eigen::Vector3d> pa = pose_at_origin(a, from_frame, Eigen::Quaterniond::Identity());
  const std::vector<Eigen::Vector3d> pb = pose_at_origin(b, to_frame, facing_turn(a, from_frame, b, to_frame));
  double moved = 0.0;
  for (size_t j = 0; j < pa.size(); ++j) moved = std::max(moved, (pa[j] - pb[j]).norm());
  double seconds = moved / kTransitionJointSpeed;
  if (ground) {
    const double speed = std::max(kTransitionMinGroundSpeed,
                                  (end_velocity(a, from_frame).norm() + start_velocity(b, to_frame).norm()) / 2.0 * a.fps);
    const double distance = on_ground(b.root_positions[to_frame] - a.root_positions[from_frame]).norm();
    seconds = std::max(seconds, distance / speed);
  }
  const int lo = std::max(1, static_cast<int>(std::lround(10.0 * a.fps / 30.0)));
  const int hi = std::max(lo, static_cast<int>(std::lround(60.0 * a.fps / 30.0)));
  const double steps = std::min(seconds * a.fps, static_cast<double>(hi) + 1.0);
  return std::clamp(static_cast<int>(std::lround(steps)) - 1, lo, hi);
}

TransitionResult run_transition(const Motion& a, const Motion& b, const TransitionRequest& request,
                                const std::string& method, int alternatives, const TaskContext& ctx) {
  check_clip(a, "A");
  check_clip(b, "B");
  int frames = checked_frames(request);
  std::vector<std::string> warnings;
  const Motion clip_b = clip_b_for(a, b, &warnings);
  const int i = resolve_frame(request.from_frame, a.num_frames(), 1, a.num_frames() - 1, "from_frame", "A",
                              "A keeps at least two frames");
  const int j = resolve_frame(request.to_frame, clip_b.num_frames(), 0, clip_b.num_frames() - 2, "to_frame", "B",
                              "B keeps at least two frames");
  const bool keep = request.place == TransitionRequest::Placement::kKeep;
  if (frames == 0) {
    frames = automatic_transition_frames(a, clip_b, i, j, keep);
    warnings.push_back("the transition has " + std::to_string(frames) +
                       " frames (chosen from the change of pose" + (keep ? " and the distance between the clips" : "") +
                       "; give a frame count to choose it)");
  }
  const Motion placed = keep ? clip_b : place_transition_clip(a, clip_b, i, j, frames);
  const Motion joined = joined_clip(a, i, placed, j, frames);
  const MotionConstraints c = transition_constraints(request, a.skeleton, i + 1, frames, joined.num_frames());
  TransitionResult out;
  static_cast<ConstrainedResult&>(out) = run_constrained(joined, c, method, alternatives, ctx);
  out.warnings.insert(out.warnings.begin(), warnings.begin(), warnings.end());
  if (request.only_transition)
    for (Motion& m : out.motions) m = m.slice(i + 1, i + 1 + frames);
  out.frames = frames;
  out.first_frame = i + 1;
  out.from_frame = i;
  out.to_frame = j;
  return out;
}

}  // namespace mf
