// Energies of the latent solvers: the constraints (tasks/constraints/motion_constraints.h)
// in their canonical form for one window of the prior, and the differentiable
// energy terms the solvers minimise over the latent codes (z_l, z_g) with the
// network frozen.
//
// Frames and coordinates. A MotionConstraints refers to frames of a Motion and
// to world coordinates (metres, Y up; prior/motion/skeleton.h). A WindowProblem
// holds the same constraints for frames [begin, begin + length) of that motion
// in the window's canonical frame (prior/model/representation.h): the ground
// transform of the *anchor* frame, a key that fixes the root, maps the window to
// the origin facing +Z. Decoded motion is compared with the targets there.
//
// Energy terms (each a weighted mean over the constrained items, so that the
// weights do not depend on how many keys there are; a zero weight disables a
// term, and what only it needs is then not computed):
//   rotation          local rotations of the non-root joints at the keys:
//                     geodesic angle (rad) through the penalty
//   position          FK positions relative to the root (canonical axes, m) of
//                     the joints whose rotation and every ancestor's rotation
//                     (root included) are constrained
//   root_orientation  geodesic angle of the root's rotation at keys that give it
//   root_translation  root path predicted by the global motion predictor (GMP)
//                     on a dense decode of the window, integrated and aligned at
//                     the anchor frame (its ground position set to the target's),
//                     against the root position of keys that give it (m)
//   effector          world (canonical) position of chosen joints at chosen
//                     frames (m), each target with its own weight
//   contact           mean squared velocity (m/s) of the joints the caller pins
//                     (MotionConstraints::contacts) over consecutive pinned frames
//   trajectory        squared ground distance (x, z; m^2) of the root from the
//                     caller's trajectory row (MotionConstraints::trajectory) at
//                     every frame that has a row and no key fixing the root
//                     position, mean over those rows
//   trajectory_facing squared difference of the root's facing unit vector
//                     (trajectory_features(), prior/model/representation.h)
//                     and the row's normalised forward, = 2 (1 - cos angle),
//                     over the same rows
//   latent_prior      0.5 * (|z_l|^2 + |z_g|^2): a Gaussian prior on the codes
//   foot_skating      mean over frames and feet of p_contact * |v_xz|^2, the
//                     horizontal foot velocity (m/s) weighted by the GMP's
//                     contact probability (detached: the solver may not turn
//                     contacts off to escape the term)
//   smoothness        mean squared second difference of the root-relative
//                     joint positions (m/s^2), on the dense decode
// The effector, contact, trajectory, foot-skating and smoothness terms are measured on the output
// motion (EnergyWeights::on_output): the decoded motion with the residual at
// each key blended in, as complete_motion() will return it, so that the
// overwrite of the known values cannot undo what they ask for.
// Penalty: Squared (default: r^2, smooth, what L-BFGS wants) or Absolute (r, with
// a 1e-6 smoothing for positions; NeMF's L1 / geodesic).
//
// What is decoded: only the key frames when no dense term is active; the whole
// window (frames 0..length-1) once when root_translation (with root keys),
// effector, contact, trajectory, foot_skating or smoothness is active, the key frames then being
// gathered from it.
#pragma once

#include <ATen/core/Tensor.h>
#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "prior/model/representation.h"
#include "prior/motion/motion.h"
#include "tasks/constraints/motion_constraints.h"
#include "tasks/latent/energy_weights.h"
#include "tasks/reference/latent_energy.h"
#include "tasks/latent/window_problem.h"
#include "tasks/latent/window_solver.h"

namespace mf {

class NemfModel;

/// The constraints of one window in its canonical frame, as tensors (float).
struct WindowProblem {
  int length = 0;   ///< T, frames of the window (2 <= T <= the model's window)
  int anchor = 0;   ///< window frame of the canonical transform (a key that fixes the root)
  GroundTransform transform;  ///< canonical -> world of the window

  // K pose keys.
  at::Tensor key_frames;          ///< [K] int64, window frames
  at::Tensor key_rotations;       ///< [K, J, 3, 3] targets (identity where unconstrained)
  at::Tensor key_rotation_mask;   ///< [K, J] 1 where the joint's rotation is constrained
  at::Tensor key_positions;       ///< [K, J, 3] root-relative FK positions of the targets, canonical axes
  at::Tensor key_position_mask;   ///< [K, J] 1 where the joint and all its ancestors are constrained
  at::Tensor key_root;            ///< [K, 3] canonical root positions (zero where unconstrained)
  at::Tensor key_root_mask;       ///< [K] 1 where the root position is constrained

  // E end-effector targets.
  at::Tensor effector_frames;   ///< [E] int64
  at::Tensor effector_joints;   ///< [E] int64
  at::Tensor effector_targets;  ///< [E, 3] canonical positions
  at::Tensor effector_weights;  ///< [E]

  // Contact pins: P steps between consecutive pinned frames, as flat
  // frame * J + joint indices.
  at::Tensor pin_from;  ///< [P] int64
  at::Tensor pin_to;    ///< [P] int64

  // R trajectory rows (MotionConstraints::followed_trajectory(): none at a
  // frame whose root position a key fixes).
  at::Tensor trajectory_frames;   ///< [R] int64
  at::Tensor trajectory_ground;   ///< [R, 2] canonical ground position (x, z)
  at::Tensor trajectory_forward;  ///< [R, 2] canonical facing (x, z), unit length

  int num_keys() const;
  int num_effectors() const;
  int num_pin_steps() const;
  int num_trajectory() const;
};

/// Builds the canonical problem of frames [begin, begin + length) of `motion`
/// under `constraints` (window-relative, i.e. already sliced), anchored at
/// window frame `anchor`, which must be a key that fixes the root. Reads only
/// what the keys constrain. Throws mf::InputError on a skeleton that does not
/// match the rig, a bad range or a bad anchor.
WindowProblem make_window_problem(const RigInfo& rig, const Motion& motion, int begin, int length,
                                  const MotionConstraints& constraints, int anchor);

/// The problem `runtime` (make_runtime_problem(), tasks/latent/window_problem.h)
/// as tensors, for a rig of `joints` joints: what make_window_problem()
/// returns for the same window.
WindowProblem to_tensor_problem(const RuntimeWindowProblem& runtime, int joints);
/// The inverse: the problem's tensors copied to float matrices and index vectors.
RuntimeWindowProblem to_runtime_problem(const WindowProblem& problem, int joints);

/// Evaluates the energy of (z_l [1, zl], z_g [1, zg]) on `problem`: the
/// active terms, weighted, in the order above (EnergyTerms, tasks/reference/latent_energy.h).
/// Differentiable with respect to the latents (the caller freezes the network).
EnergyTerms evaluate_energy(const NemfModel& model, const WindowProblem& problem, const EnergyWeights& weights,
                            const at::Tensor& z_l, const at::Tensor& z_g);

/// The solution of a window (DecodedWindow, tasks/latent/window_solver.h),
/// canonical, the GMP's root path aligned at the anchor frame.
DecodedWindow decode_window(const NemfModel& model, const WindowProblem& problem, const at::Tensor& z_l,
                            const at::Tensor& z_g);

}  // namespace mf
