#include "prior/runtime/keyframe_runtime.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "prior/inbetween/keyframe_selection.h"
#include "prior/motion/errors.h"
#include "prior/motion/rotation_kernels.h"
#include "prior/runtime/inbetween_inputs.h"
#include "prior/runtime/rotations.h"

namespace mf::runtime {

namespace {

using Matrix3Rf = Eigen::Matrix<float, 3, 3, Eigen::RowMajor>;

int trunk_inputs(const RigInfo& rig) { return rig.num_joints() * 7 + 4 + kTrajectorySize; }

Matrix3Rf root_rotation(const MatrixRXf& pose, Eigen::Index t) {
  Matrix3Rf r;
  kernels::sixd_to_matrix(pose.row(t).data(), r.data());
  return r;
}

// Poses [T, D] (raw) moved onto the trajectory: the root's ground x, z set to
// the trajectory's, the root rotation turned about +Y to its facing.
MatrixRXf follow_trajectory(const MatrixRXf& pose, const MatrixRXf& trajectory, const RigInfo& rig) {
  MatrixRXf out = pose;
  const Eigen::Index D = pose.cols();
  for (Eigen::Index t = 0; t < pose.rows(); ++t) {
    const Matrix3Rf root = root_rotation(pose, t);
    float facing[2];
    ground_facing(root.data(), rig, facing);
    const float delta = std::atan2(trajectory(t, 2), trajectory(t, 3)) - std::atan2(facing[0], facing[1]);
    const float c = std::cos(delta), s = std::sin(delta);
    Matrix3Rf turn;
    turn << c, 0, s, 0, 1, 0, -s, 0, c;
    const Matrix3Rf turned = turn * root;
    out.row(t).head(6) << turned.col(0).transpose(), turned.col(1).transpose();
    out(t, D - 3) = trajectory(t, 0);
    out(t, D - 1) = trajectory(t, 1);
  }
  return out;
}

// The picked keyframes of a window (select_keyframes in keyframe_net.h).
std::vector<bool> picked_keyframes(const Eigen::VectorXf& logits, const std::vector<bool>& anchors,
                                   const std::vector<bool>& valid, const KeyframeConfig& c) {
  const int T = static_cast<int>(logits.size());
  std::unique_ptr<bool[]> a(new bool[T]), v(new bool[T]), picked(new bool[T]);
  for (int t = 0; t < T; ++t) a[t] = anchors[t], v[t] = valid[t], picked[t] = false;
  select_window_keyframes(logits.data(), a.get(), v.get(), T, c.min_spacing, c.max_spacing, picked.get());
  return std::vector<bool>(picked.get(), picked.get() + T);
}

// Facing directions [T, 2] interpolated between the known rows and
// normalised; where that cancels out, the previous known facing (the next
// one before the first, +z without any).
MatrixRXf interpolated_facing(const MatrixRXf& facing, const std::vector<bool>& known) {
  const int T = static_cast<int>(facing.rows());
  const float floor = static_cast<float>(kMinFacingNorm);
  const MatrixRXf f = interpolate_known(facing, known);
  MatrixRXf out(T, 2);
  int prev = -1;
  for (int t = 0; t < T; ++t) {
    if (known[t]) prev = t;
    int held_row = prev;
    if (held_row < 0) held_row = static_cast<int>(std::find(known.begin(), known.end(), true) - known.begin());
    const bool held = held_row < T && known[held_row];
    const float norm = f.row(t).norm(), held_norm = held ? facing.row(held_row).norm() : 0.0f;
    if (norm > floor) {
      out.row(t) = f.row(t) / std::max(norm, floor);
    } else if (held_norm > floor) {
      out.row(t) = facing.row(held_row) / std::max(held_norm, floor);
    } else {
      out(t, 0) = 0.0f;
      out(t, 1) = 1.0f;
    }
  }
  return out;
}

}  // namespace

void ground_facing(const float* root, const RigInfo& rig, float* facing) {
  const float w[3] = {static_cast<float>(rig.root_forward.x()), static_cast<float>(rig.root_forward.y()),
                      static_cast<float>(rig.root_forward.z())};
  float h[9];
  kernels::heading_rotation(root, w, h);
  facing[0] = h[2];
  facing[1] = h[8];
}

MatrixRXf interpolate_trajectory_rows(const MatrixRXf& rows, const std::vector<bool>& xz_known,
                                      const std::vector<bool>& facing_known) {
  MatrixRXf out(rows.rows(), kTrajectorySize);
  out << interpolate_known(rows.leftCols(2), xz_known), interpolated_facing(rows.rightCols(2), facing_known);
  return out;
}

MatrixRXf interpolated_trajectory(const MatrixRXf& pose, const MatrixRXf& known, const RigInfo& rig) {
  const Eigen::Index T = pose.rows(), J = rig.num_joints(), D = pose.cols();
  MatrixRXf rows(T, kTrajectorySize);
  for (Eigen::Index t = 0; t < T; ++t) {
    rows(t, 0) = pose(t, D - 3);
    rows(t, 1) = pose(t, D - 1);
    ground_facing(root_rotation(pose, t).data(), rig, &rows(t, 2));
  }
  return interpolate_trajectory_rows(rows, flags_of(known.col(J)), flags_of(known.col(0)));
}

MatrixRXf interpolate_keyframe_poses(const MatrixRXf& poses, const std::vector<bool>& keys, int joints) {
  const int T = static_cast<int>(poses.rows()), D = 6 * joints + 3;
  MatrixRXf out(T, D), rotations;
  sixd_to_matrix(poses.leftCols(6 * joints), &rotations);
  int prev = -1;
  for (int t = 0; t < T; ++t) {
    if (keys[t]) prev = t;
    const int next = static_cast<int>(std::find(keys.begin() + t, keys.end(), true) - keys.begin());
    const int p = std::clamp(prev >= 0 ? prev : next, 0, T - 1), n = std::clamp(next < T ? next : prev, 0, T - 1);
    const float w = std::clamp(static_cast<float>(t - p) / static_cast<float>(std::max(n - p, 1)), 0.0f, 1.0f);
    for (int j = 0; j < joints; ++j) {
      const Quaternion4f q = quat_slerp(matrix_to_quat(&rotations(p, 9 * j)), matrix_to_quat(&rotations(n, 9 * j)), w);
      Matrix3Rf m;
      quat_to_matrix(q, m.data());
      out.row(t).segment(6 * j, 6) << m.col(0).transpose(), m.col(1).transpose();
    }
    out.row(t).tail(3) = poses.row(p).tail(3) + (poses.row(n).tail(3) - poses.row(p).tail(3)) * w;
  }
  return out;
}

KeyframeRuntime::KeyframeRuntime(const KeyframeConfig& config, const RigInfo& rig,
                                 InbetweenNormalisation normalisation, WeightReader& w)
    : InbetweenerRuntime(rig, std::move(normalisation)),
      config_(config),
      keyframe_(w, "keyframe", config.trunk(), trunk_inputs(rig), rig.num_joints() * 6 + 4, true),
      refine_(w, "refine", config.trunk(), trunk_inputs(rig) + 1, rig.num_joints() * 6 + 3 + rig.num_feet(), false) {}

void KeyframeRuntime::forward(const InbetweenWindow& in, InbetweenResult* out) const {
  const int T = checked_frames(in, config_.window, "keyframe");
  const int J = rig().num_joints(), D = pose_size(), R = 6 * J;
  const InbetweenNormalisation& n = normalisation();
  const bool given = in.trajectory.rows() > 0;
  if (given && (in.trajectory.rows() != T || in.trajectory.cols() != kTrajectorySize)) {
    throw InputError("keyframe: trajectory must be [T, 4] matching pose");
  }
  const MaskedWindow m = masked_window(in, n, J);
  const MatrixRXf trajectory = given ? in.trajectory : interpolated_trajectory(in.pose, m.known, rig());
  const MatrixRXf x = masked_pose_input(in, m, n, J);
  MatrixRXf traj(T, kTrajectorySize);
  traj << (trajectory.col(0).array() - n.mean[R]) / n.scale[R], (trajectory.col(1).array() - n.mean[R + 2]) / n.scale[R + 2],
      trajectory.rightCols(2);
  for (int t = 0; t < T; ++t) {
    if (!m.valid[t]) traj.row(t).setZero();
  }
  const RowVectorXf valid_mask = additive_mask(m.valid);
  const MatrixRXf offsets = offset_features(T, config_.window);
  MatrixRXf k_out, r_out;
  MatrixRXf k_in(T, D + J + 1 + kTrajectorySize);
  k_in << x, m.known, traj;
  keyframe_.forward(k_in, key_features(m.key, config_.window), valid_mask, offsets, &k_out);
  *out = InbetweenResult();
  out->keyframe_poses = denormalised(k_out.leftCols(D), n);
  out->keyframe_logits = k_out.col(D);

  // Selection and interpolation through the known values and KeyframeNet's picks.
  const std::vector<bool> picked = picked_keyframes(out->keyframe_logits, m.key, m.valid, config_);
  const int last_valid = static_cast<int>(std::find(m.valid.rbegin(), m.valid.rend(), true) - m.valid.rbegin());
  std::vector<bool> anchors(T);
  out->keyframes.resize(T);
  for (int t = 0; t < T; ++t) {
    anchors[t] = m.key[t] || picked[t] || t == T - 1 - last_valid;
    out->keyframes[t] = anchors[t] && m.valid[t] ? 1.0f : 0.0f;
  }
  const MatrixRXf predicted = given ? follow_trajectory(out->keyframe_poses, trajectory, rig()) : out->keyframe_poses;
  const MatrixRXf interpolated =
      interpolate_keyframe_poses(where_known(m.channel_known, in.pose, predicted), flags_of(out->keyframes), J);
  const MatrixRXf i_norm = ((interpolated.array().rowwise() - n.mean.array()).rowwise() / n.scale.array()).matrix();
  MatrixRXf r_in(T, k_in.cols() + 1);
  Eigen::VectorXf flags(T);
  for (int t = 0; t < T; ++t) flags[t] = anchors[t] ? 1.0f : 0.0f;
  r_in << i_norm, m.known, traj, flags;
  refine_.forward(r_in, MatrixRXf(), valid_mask, offsets, &r_out);
  out->stages = {interpolated, denormalised(i_norm + r_out.leftCols(D), n)};
  out->contact_logits = r_out.rightCols(rig().num_feet());
}

}  // namespace mf::runtime
