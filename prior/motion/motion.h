// Motion: the one representation of an animation that flows through motionfield.
// Units and axes: see skeleton.h (metres, Y-up, quaternions (w, x, y, z)).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "prior/motion/skeleton.h"

namespace mf {

struct Motion {
  Skeleton skeleton;
  double fps = 30.0;
  /// Local joint rotations, frame-major: rotations[f * J + j].
  std::vector<Eigen::Quaterniond> rotations;
  /// Root (joint 0) translation per frame, metres, world frame.
  std::vector<Eigen::Vector3d> root_positions;

  int num_joints() const { return skeleton.num_joints(); }
  int num_frames() const { return static_cast<int>(root_positions.size()); }
  double frame_time() const { return 1.0 / fps; }

  Eigen::Quaterniond& rotation(int frame, int joint) { return rotations[static_cast<size_t>(frame) * num_joints() + joint]; }
  const Eigen::Quaterniond& rotation(int frame, int joint) const {
    return rotations[static_cast<size_t>(frame) * num_joints() + joint];
  }

  /// A motion of `frames` frames on `skeleton`, every rotation identity, root at
  /// the origin. Throws mf::InputError if frames < 0.
  static Motion identity(const Skeleton& skeleton, int frames, double fps);

  /// Frames [begin, end) as a new motion. Throws mf::InputError unless
  /// 0 <= begin <= end <= num_frames() (an empty slice is allowed).
  Motion slice(int begin, int end) const;

  /// Throws mf::InputError unless the skeleton is valid, sizes agree, fps > 0 and
  /// every value is finite, and every quaternion has a norm of at least 1e-6
  /// (quaternions need not be exactly unit: consumers normalise).
  void validate() const;
};

/// Global (world) joint positions and rotations of every frame, frame-major like
/// Motion::rotations. Double precision, for I/O, metrics and single poses; the
/// batched differentiable version is in kinematics_torch.h.
struct GlobalPose {
  int frames = 0;
  int joints = 0;
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Quaterniond> rotations;
  const Eigen::Vector3d& position(int f, int j) const { return positions[static_cast<size_t>(f) * joints + j]; }
  const Eigen::Quaterniond& rotation(int f, int j) const { return rotations[static_cast<size_t>(f) * joints + j]; }
};

/// G_j = G_parent * T(offset_j) * R_j; the root uses root_positions[f] instead of
/// its offset. Local rotations are normalised on the way. The motion is not
/// validated: call validate() first on untrusted input.
GlobalPose forward_kinematics(const Motion& motion);

}  // namespace mf
