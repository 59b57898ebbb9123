// One window's constraints in its canonical frame, without tensors: what the
// latent solvers' energy (tasks/latent/runtime_energy.h) compares the decoded
// motion with.
//
// Frames and coordinates. A MotionConstraints refers to frames of a Motion and
// to world coordinates (metres, Y up; prior/motion/skeleton.h). A window
// problem holds the same constraints for frames [begin, begin + length) of that
// motion in the window's canonical frame (prior/model/canonical_window.h): the
// ground transform of the *anchor* frame, a key that fixes the root, maps the
// window to the origin facing +Z.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "prior/model/canonical_window.h"
#include "prior/model/rig_info.h"
#include "prior/motion/motion.h"
#include "prior/runtime/tensor_ops.h"
#include "tasks/constraints/motion_constraints.h"

namespace mf {

/// The constraints of one window in its canonical frame as float matrices
/// (one row per key, effector or trajectory row; J joints).
struct RuntimeWindowProblem {
  int length = 0;                        ///< T, frames of the window (2 <= T <= the model's window)
  int anchor = 0;                        ///< window frame of the canonical transform (a key that fixes the root)
  GroundTransform transform;             ///< canonical -> world of the window
  std::vector<int> key_frames;           ///< [K] window frames
  runtime::MatrixRXf key_rotations;      ///< [K, J * 9] targets, row-major 3x3 per joint (identity where unconstrained)
  runtime::MatrixRXf key_rotation_mask;  ///< [K, J] 1 where the joint's rotation is constrained
  runtime::MatrixRXf key_positions;      ///< [K, J * 3] root-relative FK positions of the targets, canonical axes
  runtime::MatrixRXf key_position_mask;  ///< [K, J] 1 where the joint and its ancestors are constrained
  runtime::MatrixRXf key_root;           ///< [K, 3] canonical root positions (zero where unconstrained)
  Eigen::VectorXf key_root_mask;         ///< [K] 1 where the root position is constrained

  // E end-effector targets.
  std::vector<int> effector_frames;     ///< [E] window frames
  std::vector<int> effector_joints;     ///< [E]
  runtime::MatrixRXf effector_targets;  ///< [E, 3] canonical positions
  Eigen::VectorXf effector_weights;     ///< [E]

  /// Contact pins: P steps between consecutive pinned frames, as flat
  /// frame * J + joint indices.
  std::vector<int> pin_from, pin_to;

  // R trajectory rows (MotionConstraints::followed_trajectory(): none at a
  // frame whose root position a key fixes).
  std::vector<int> trajectory_frames;     ///< [R] window frames
  runtime::MatrixRXf trajectory_ground;   ///< [R, 2] canonical ground position (x, z)
  runtime::MatrixRXf trajectory_forward;  ///< [R, 2] canonical facing (x, z), unit length

  int num_keys() const { return static_cast<int>(key_frames.size()); }
  int num_effectors() const { return static_cast<int>(effector_frames.size()); }
  int num_pin_steps() const { return static_cast<int>(pin_from.size()); }
  int num_trajectory() const { return static_cast<int>(trajectory_frames.size()); }
};

/// The solution of a window, canonical: local rotations [T, J * 9] (row-major
/// 3x3 per joint, joint 0's the root's in the canonical frame) at frames
/// 0..T-1, the global motion predictor's root path [T, 3] and its foot
/// contact probabilities [T, F] (RigInfo::foot_joints order).
struct DecodedWindow {
  runtime::MatrixRXf local_rotations;
  runtime::MatrixRXf root_positions;
  runtime::MatrixRXf contacts;
};

/// Builds the canonical problem of frames [begin, begin + length) of `motion`
/// under `constraints` (window-relative, i.e. already sliced), anchored at
/// window frame `anchor`, which must be a key that fixes the root. Reads only
/// what the keys constrain. Throws mf::InputError on a skeleton that does not
/// match the rig, a bad range, a bad anchor, or an effector, contact or
/// trajectory row outside the window or on a joint the rig lacks.
RuntimeWindowProblem make_runtime_problem(const RigInfo& rig, const Motion& motion, int begin, int length,
                                          const MotionConstraints& constraints, int anchor);

}  // namespace mf
