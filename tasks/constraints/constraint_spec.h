// The constraints of a request as a caller writes them: joints by name,
// positions in the input's own length unit. One description for every
// interface: the constraints file (JSON, docs/CONSTRAINTS.md) of the CLI and
// batch jobs, the C ABI's mf_constraints (and so Python). resolve() turns it
// into the MotionConstraints of a given motion (tasks/constraints/motion_constraints.h).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "prior/motion/skeleton.h"
#include "tasks/constraints/motion_constraints.h"

namespace mf {

/// A key: the whole pose (`whole`), or the local rotations of `joints` and
/// the root's rotation and/or position.
struct KeySpec {
  int frame = 0;
  bool whole = true;
  std::vector<std::string> joints;
  bool root_rotation = false, root_position = false;
};

/// An end-effector target: `joint`'s world position at `frame`, in the
/// input's units, with a relative weight.
struct TargetSpec {
  int frame = 0;
  std::string joint;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double weight = 1.0;
};

/// A contact pin: `joint` stays put from `first` to `last` (inclusive).
struct ContactSpec {
  std::string joint;
  int first = 0, last = 0;
};

struct ConstraintSpec {
  std::vector<KeySpec> keys;
  std::vector<TargetSpec> targets;
  std::vector<ContactSpec> contacts;
  /// The ground trajectory (TrajectoryPoint rows, x and z in the input's
  /// unit; any order here, sorted by frame by resolve()).
  std::vector<TrajectoryPoint> trajectory;

  /// Parses the constraints file format (docs/CONSTRAINTS.md). Throws
  /// mf::InputError, prefixed with `source`, on invalid JSON, unknown fields,
  /// wrong types, non-integer frames, non-finite or negative weights, keys
  /// that constrain nothing, and trajectory rows with a zero-length facing.
  static ConstraintSpec parse_json(const std::string& text, const std::string& source = "constraints");

  /// Appends the constraints of `other` (frames and names as they are).
  void append(const ConstraintSpec& other);
  /// Appends whole-pose keys at `frames`.
  void add_whole_pose_keys(const std::vector<int>& frames);

  /// The constraints on `skeleton`, positions (targets, trajectory x and z)
  /// scaled by `length_scale` (metres per input unit), keys and trajectory
  /// rows sorted by frame; keys at one frame are merged into
  /// one that constrains what either does (a whole pose covers everything).
  /// Throws mf::InputError on an unknown joint name (listing the skeleton's);
  /// the rest is checked by MotionConstraints::validate().
  MotionConstraints resolve(const Skeleton& skeleton, double length_scale) const;

  /// The same description as JSON text (parse_json() reads it back; the
  /// "trajectory" member only when there are rows).
  std::string to_json() const;
};

}  // namespace mf
