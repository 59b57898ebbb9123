// What the animator asks of a motion to complete: pose keys (full or
// partial: some joints' rotations, with or without the root position) and
// end-effector targets, in the frames and world coordinates of a Motion
// (metres, Y up; prior/motion/skeleton.h).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "prior/motion/motion.h"

namespace mf {

/// A pose constraint at one frame: the local rotations of `joints` (joint 0's
/// is the root's world rotation) and, if `root_position`, the root's world
/// position, as the input motion holds them at that frame. Nothing else of the
/// frame is read.
struct PoseKey {
  int frame = 0;
  std::vector<int> joints;     ///< constrained joints, increasing; empty means every joint
  bool root_position = true;   ///< the root translation is constrained too
  /// False: no rotation at all is constrained (`joints` must be empty): a key
  /// of the root position alone.
  bool rotations = true;
};

/// An end-effector target: the world position (metres) of `joint` at `frame`,
/// without a pose. The solver's energy pulls toward it with the effector
/// weight times `weight`; complete_motion() then places the joint by IK
/// (tasks/latent/latent_solver.h).
struct EffectorTarget {
  int frame = 0;
  int joint = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double weight = 1.0;
};

/// A contact the caller pins: `joint` (a foot, a hand on a rail) does not move
/// in the world from frame `first` to frame `last` (inclusive). Where it is held
/// is the solver's choice unless keys inside the range fix it (then it is held
/// at their positions; tasks/fixups/foot_locking.h pin_contacts()).
struct ContactPin {
  int joint = 0;
  int first = 0, last = 0;
};

/// One row of the ground trajectory the caller asks for: where the root is on
/// the ground at `frame` (world x and z, metres) and which way it faces (the
/// root's heading, prior/model/representation.h: a horizontal direction,
/// normalised on validation). Rows at frames whose root position a key fixes
/// are ignored (the known frames win).
struct TrajectoryPoint {
  int frame = 0;
  double x = 0, z = 0;
  double forward_x = 0, forward_z = 1;
};

/// The one order check of keyframes, whether a task's list
/// (tasks/methods/jobs.h validate_keyframes) or the keys of MotionConstraints:
/// throws mf::InputError unless `frame` comes after `previous`, the keyframe
/// before it ("keyframe F is given twice", "keyframes must be in increasing
/// order (P is followed by F)").
void check_keyframe_order(int previous, int frame);

/// Everything known about a motion to complete.
struct MotionConstraints {
  std::vector<PoseKey> keys;              ///< strictly increasing frames
  std::vector<EffectorTarget> effectors;  ///< any order, any frames in range
  std::vector<ContactPin> contacts;       ///< any order; pins of one joint must not overlap
  std::vector<TrajectoryPoint> trajectory;  ///< strictly increasing frames, any subset of the frames

  /// Full-pose keys (every joint and the root position) at `frames`.
  static MotionConstraints full_pose(const std::vector<int>& frames);

  /// Throws mf::InputError unless: keys are in range and strictly increasing
  /// (check_keyframe_order()), key joints are in range, increasing and unique,
  /// effector frames and joints are in range with finite positions and
  /// non-negative finite weights,
  /// trajectory rows are in range, strictly increasing, finite, with a facing
  /// direction of non-zero length (|(forward_x, forward_z)| >= 1e-6), and at
  /// least one key fixes the root (rotation of joint 0 and root position), which
  /// the canonical frame needs.
  void validate(int frames, int joints) const;

  /// Throws mf::InputError naming the joint and frame unless the values the
  /// keys read from `input` are usable: finite, non-zero rotations and finite
  /// root positions (call after validate()).
  void check_values(const Motion& input) const;

  /// True when key `k` constrains `joint`'s rotation.
  bool key_has_joint(size_t k, int joint) const;
  /// True when key `k` gives the root's rotation and position (it can anchor a window).
  bool key_fixes_root(size_t k) const;
  /// True when a key fixes the root's position at `frame`.
  bool fixes_root_position(int frame) const;
  /// The trajectory rows the solvers follow: those at frames where no key
  /// fixes the root position (the known frames win).
  std::vector<TrajectoryPoint> followed_trajectory() const;
  /// True when anything but whole-pose keys is asked for (partial keys,
  /// end-effector targets, contact pins or a trajectory).
  bool beyond_full_poses() const;
  /// Constraints of frames [begin, begin + length), renumbered from 0 (contact
  /// pins clipped to the range, dropped when less than two frames remain;
  /// trajectory rows outside the range dropped).
  MotionConstraints slice(int begin, int length) const;

 private:
  void validate_contacts(int frames, int joints) const;
  void validate_trajectory(int frames) const;
};

}  // namespace mf
