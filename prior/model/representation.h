// The prior's view of motion: canonical windows as batched float tensors, the
// local-motion features its encoder reads, and the quantities its global
// motion predictor (GMP) is trained on. Everything here is differentiable where
// the solvers need it, and shared by training, the tasks and the benchmark.
//
// Canonical frame of a window: translated so that the root's ground position at
// the anchor frame (frame 0 unless said otherwise) is the origin, and turned
// about +Y so that the root's heading at the anchor frame is +Z.
//
// Heading: the root's forward axis (a unit vector in the root's local frame,
// RigInfo::root_forward) mapped to the world, projected on the ground; H(t) is
// the rotation about +Y by yaw(t) = atan2(f.x, f.z), so H(t) * (0, 0, 1) is the
// heading direction.
//
// Tensor layout used throughout (B windows, T frames, J joints, float32):
//   local_rotations [B, T, J, 3, 3]  parent-relative; joint 0's is the root's
//                                    global rotation in the canonical frame
//   root_positions  [B, T, 3]        metres, canonical frame
#pragma once

#include <ATen/core/Tensor.h>
#include <string>
#include <vector>

#include "prior/model/canonical_window.h"  // GroundTransform, canonical_transform(), window_matrices()
#include "prior/model/rig_info.h"            // RigInfo, find_foot_joints(), measure_rig()
#include "prior/motion/motion.h"

namespace mf {

/// Motion frames [begin, begin + length) as tensors [1, length, ...] in the
/// canonical frame of frame `begin + anchor`.
struct WindowTensors {
  at::Tensor local_rotations;  ///< [1, T, J, 3, 3]
  at::Tensor root_positions;   ///< [1, T, 3]
};
WindowTensors window_tensors(const Motion& motion, int begin, int length, const RigInfo& rig, int anchor = 0);

/// Writes canonical tensors (one window, [T, ...] or [1, T, ...]) back into
/// `motion` frames [begin, begin + T), undoing `transform`.
void write_window(const at::Tensor& local_rotations, const at::Tensor& root_positions,
                  const GroundTransform& transform, Motion* motion, int begin);

/// The ground-plane coordinates (x, z) of points [..., 3] -> [..., 2].
at::Tensor ground_xz(const at::Tensor& points);

/// Heading rotations H(t) [..., 3, 3] from root rotations [..., 3, 3]: the
/// rotation about +Y that turns +Z to the root's forward axis projected on the
/// ground (one autograd node; floating-point input, else InputError).
at::Tensor heading_rotation(const at::Tensor& root_rotations, const Eigen::Vector3d& root_forward);

/// The ground trajectory of a motion, [..., 4] per frame: the root's ground
/// position (x, z; the positions' unit) and its facing direction (the heading's
/// forward unit vector, forward_x = sin(yaw), forward_z = cos(yaw)), from root
/// rotations [..., 3, 3] and root positions [..., 3] in the same frame. The
/// row format of MotionConstraints::trajectory (tasks/constraints/motion_constraints.h).
at::Tensor trajectory_features(const at::Tensor& root_rotations, const at::Tensor& root_positions,
                               const Eigen::Vector3d& root_forward);

/// Per-frame local-motion features of the encoder, [B, T, J, 15]: root-relative
/// joint positions in the heading frame (3), their velocities (3, central
/// differences, one-sided at the ends, per second), the 6D of each joint's
/// global rotation with the heading removed (6) and its angular velocity (3,
/// rad/s). Root orientation (6D, canonical frame) is returned in `root6d`
/// [B, T, 6] for the global encoder.
at::Tensor local_features(const at::Tensor& local_rotations, const RigInfo& rig, double fps, at::Tensor* root6d);

/// Root-relative joint positions with the heading removed, [B, T, J, 3]; the
/// GMP's main input.
at::Tensor heading_relative_positions(const at::Tensor& local_rotations, const RigInfo& rig);

/// The GMP's per-frame input, [B, T, J * 3 + 6]: heading-relative joint
/// positions and the 6D of the root rotation with the heading removed.
at::Tensor gmp_inputs(const at::Tensor& local_rotations, const RigInfo& rig);

/// The same from the joint positions [B, T, J, 3] that forward kinematics of
/// `local_rotations` gives with the root at the origin (its orientation kept):
/// a caller that needs those positions anyway saves a second FK pass.
at::Tensor gmp_inputs(const at::Tensor& local_rotations, const at::Tensor& positions_at_origin, const RigInfo& rig);

/// GMP targets from ground truth: root velocity in the heading frame (m/s,
/// forward differences, the last frame repeats) [B, T, 3], root height [B, T, 1]
/// and foot contacts in {0, 1} [B, T, F].
struct GmpTargets {
  at::Tensor velocity;
  at::Tensor height;
  at::Tensor contacts;
};
GmpTargets gmp_targets(const at::Tensor& local_rotations, const at::Tensor& root_positions, const RigInfo& rig,
                       double fps);

/// Root translation from heading-frame velocities: forward-Euler integration
/// of the horizontal velocity from `start_xz` [B, 2] (the canonical origin when
/// undefined), height set directly. [B, T, 3].
at::Tensor integrate_root(const at::Tensor& velocity, const at::Tensor& height, const at::Tensor& headings,
                          double fps, const at::Tensor& start_xz = {});

}  // namespace mf
