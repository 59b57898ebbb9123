// How well a motion meets its constraints (tasks/constraints/motion_constraints.h): the
// error at the keys, at the end-effector targets and over the contact pins,
// measured on any motion (the raw solution of a solver, or what a task
// returns), in degrees and centimetres.
#pragma once

#include "prior/motion/motion.h"
#include "tasks/constraints/motion_constraints.h"

namespace mf {

/// Error at the constrained values of the keys.
struct ConstraintError {
  double rotation_max_deg = 0.0, rotation_mean_deg = 0.0;  ///< constrained local rotations (root included)
  double root_max_cm = 0.0, root_mean_cm = 0.0;            ///< constrained root positions
  long rotations = 0, roots = 0;                           ///< counts
};

/// Distance of each end-effector target's joint from its target.
struct EffectorError {
  double max_cm = 0.0, mean_cm = 0.0;
  long count = 0;
};

/// Sliding over the contact pins: the distance of the pinned joint at each
/// frame of a pin from where it is at the pin's first frame.
struct ContactError {
  double max_cm = 0.0, mean_cm = 0.0;
  long frames = 0;  ///< pinned frames measured (all pins)
};

/// How closely the root follows the trajectory rows the solvers follow
/// (MotionConstraints::followed_trajectory()): the ground distance (x, z) of
/// the root from each row, and the angle between the root's facing (its
/// heading, trajectory_features() of prior/model/representation.h) and the
/// row's forward direction.
struct TrajectoryError {
  double max_cm = 0.0, mean_cm = 0.0;
  double facing_max_deg = 0.0, facing_mean_deg = 0.0;
  long rows = 0;  ///< rows measured
};

struct ConstraintReport {
  ConstraintError keys;
  EffectorError targets;
  ContactError contacts;
  TrajectoryError trajectory;
};

/// Keys of `c` in `motion` against `input` (which holds the key values).
ConstraintError key_error(const Motion& input, const MotionConstraints& c, const Motion& motion);
/// End-effector targets of `c` in `motion`.
EffectorError effector_error(const Motion& motion, const MotionConstraints& c);
/// Contact pins of `c` in `motion`.
ContactError contact_error(const Motion& motion, const MotionConstraints& c);
/// Trajectory rows of `c` in `motion`; `root_forward` is the root-local axis
/// that points forward (RigInfo::root_forward of the model's rig).
TrajectoryError trajectory_error(const Motion& motion, const MotionConstraints& c,
                                 const Eigen::Vector3d& root_forward = Eigen::Vector3d::UnitZ());
/// The four above.
ConstraintReport measure_constraints(const Motion& input, const MotionConstraints& c, const Motion& motion,
                                     const Eigen::Vector3d& root_forward = Eigen::Vector3d::UnitZ());

}  // namespace mf
