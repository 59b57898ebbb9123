// How a transformer in-betweener (prior/runtime/inbetween_runtime.h) fills a
// motion in one pass: inbetweener_fill(), behind the transformer methods
// (tasks/methods/transformer_methods.h) and the transformer initialisers of the latent
// solvers (tasks/latent/initializers.h).
//
//  * Keys that fix the root (root rotation and root position, see
//    MotionConstraints::key_fixes_root) bound the gaps: every run of frames
//    between two consecutive such keys is a gap. Partial keys inside a gap are
//    given to the model with their known mask (per joint, root position).
//  * Windows start at a key that fixes the root (the window is canonical
//    there, as in training) and end at one, hold at most model.window()
//    frames, and are given the keys of the last up to 10 frames before the
//    gap they fill as context (or, when the keys are sparse, the previous key
//    if it is at most 40 frames back): the known patterns of training. A
//    window extends over as many following gaps as fit. Each gap is produced
//    by exactly one window, so the pieces meet only at known frames.
//  * A gap longer than the window (two keys more than window() - 1 frames
//    apart) cannot be filled by one pass: LongGapPolicy::Throw says so with
//    mf::InputError (the methods), LongGapPolicy::Interpolate leaves that gap
//    interpolated (the initialisers, where the solver refines it anyway).
//  * Frames before the first and after the last key that fixes the root, and
//    the unconstrained joints of those keys, are filled like
//    fill_by_interpolation() of tasks/constraints/interpolation_fill.h (held before the first and
//    after the last key).
//  * Constrained values come out exactly as given (copied from the input);
//    no other value of the input is read. So that the output does not jump
//    next to a key where the model's own output misses it, the residual at
//    the two keys that bound a gap (per joint where the key gives it, and the
//    root position) is spread over the gap with smoothstep weights, each
//    key's residual fading from full next to it to none at the other key
//    (the two residual rotations composed; unlike tasks/constraints/residuals.h, which
//    interpolates between them).
//  * A ground trajectory (constraints.trajectory, world x, z and facing) goes
//    to the model as InbetweenWindow::trajectory, in each window's canonical
//    frame (canonical_trajectory()), for the kinds that read it (the others
//    ignore it): constrained_trajectory() completes it over every frame (the
//    keys' own root wins over a row at the same frame; frames without a row
//    are interpolated). Without trajectory rows the window has none and a
//    trajectory-conditioned kind interpolates between the known roots itself.
//    Callers (CLI, C ABI, batch) only fill MotionConstraints::trajectory.
//  * Jumps at the keys (`fallback.interpolate_jumps`): a gap whose output
//    jumps where it leaves or reaches its keys by more than a body can
//    (implausible_seam() of tasks/constraints/seams.h: the model answered with a
//    pose of its own, as on motion unlike its training data) is interpolated
//    like fill_by_interpolation(), and a sentence says so.
//  * Foot locking (`foot_lock`): when the model predicts foot contacts (its
//    contact head reads the last stage, so only when that stage is used),
//    lock_feet() of tasks/fixups/foot_locking.h holds the planted ankles with those
//    contacts, as after a latent solve (the frames of keys that constrain a
//    leg untouched). Measured in docs/BENCHMARKS.md ("Long transitions").
//  * The input's frames are taken as frames of the model (no resampling to
//    the model's fps). Deterministic.
#pragma once

#include <string>
#include <vector>

#include "prior/model/canonical_window.h"
#include "prior/runtime/tensor_ops.h"
#include "prior/motion/motion.h"
#include "tasks/constraints/motion_constraints.h"

namespace mf {

namespace runtime {
class InbetweenerRuntime;
}

enum class LongGapPolicy {
  Throw,        ///< mf::InputError naming the keys and the window
  Interpolate,  ///< that gap stays interpolated
};

/// What inbetweener_fill() does where the model's output jumps at its keys
/// (see the top of this file).
struct FillFallback {
  bool interpolate_jumps = false;
  /// Where the sentence about interpolated gaps goes (may be null).
  std::vector<std::string>* warnings = nullptr;
};

/// Completes `input` under `constraints` (full or partial keys; end-effector
/// targets are ignored) with one pass of `model`, using the output of stage
/// `stage` (0-based; -1 = the last stage). See the top of this file. Throws
/// mf::InputError for constraints that do not validate, a skeleton whose
/// joint count differs from the model's, a stage the model does not have, or
/// (LongGapPolicy::Throw) a gap longer than the window.
Motion inbetweener_fill(const runtime::InbetweenerRuntime& model, int stage, const Motion& input,
                        const MotionConstraints& constraints, LongGapPolicy policy,
                        bool foot_lock = false, const FillFallback& fallback = {});

/// The ground trajectory of every frame of `input`, [frames, 4] (world:
/// x, z, forward_x, forward_z as trajectory_features() of
/// prior/model/representation.h), that `constraints` ask for: the rows of
/// constraints.trajectory, except at keys that give the root position (x, z)
/// or the root rotation (facing), whose own values win; the other frames
/// interpolated between those (interpolate_trajectory_rows() of
/// prior/runtime/keyframe_runtime.h: linear, facing normalised, held at the
/// ends). No rows (0 x 4) when constraints.trajectory is empty.
runtime::MatrixRXf constrained_trajectory(const Motion& input, const MotionConstraints& constraints,
                                          const RigInfo& rig);

/// World trajectory rows [n, 4] in the canonical frame of `transform`
/// (canonical = R_y(-yaw) (world - (x, 0, z)); the facing only rotated).
runtime::MatrixRXf canonical_trajectory(const Eigen::Ref<const runtime::MatrixRXf>& world,
                                        const GroundTransform& transform);

}  // namespace mf
