// Transitions between two clips: the end of clip A (up to frame I) and the
// start of clip B (from frame J) with N generated frames between them, as one
// clip on A's rig at A's frame rate:
//
//   output = A[0..I]  (I + 1 frames, exactly as given)
//          + N generated frames (output frames I + 1 .. I + N)
//          + B[J..]  (B's frames from J to its end, exactly as given after
//                     placement)
//
// How it is built:
//   1. B onto A's rig (transition_onto_rig_of): the same joint names in any
//      order are reordered to A's; the same hierarchy (parents) under other
//      names is mapped joint by joint in order; anything else is an
//      InputError naming the first difference. A's skeleton (offsets
//      included) carries the result. B at another frame rate is resampled to
//      A's with the "cubic" spline (run_resample; deterministic, no model),
//      with a warning saying so.
//   2. Placement (TransitionRequest::place). kAuto moves and turns B on the
//      ground (about +Y, the vertical of prior/motion/skeleton.h; B's heights
//      are untouched) so that its frame J continues A's frame I:
//        - facing: B is turned by the yaw (the twist about +Y) of the
//          rotation that takes B's root orientation at J to A's root
//          orientation at I, so B starts facing the way A ends;
//        - position: B's root at J is put where A's root arrives from frame I
//          in the N + 1 frame steps to it at the mean of A's end ground
//          velocity and B's start ground velocity (each the mean over at most
//          kTransitionVelocityFrames frame steps at the seam, B's turned with
//          B): p_J = p_I + (N + 1) * (v_A + v_B) / 2 on the ground.
//      kKeep leaves B where it is (bit for bit).
//   3. The concatenated clip is completed with whole-pose keys on every frame
//      of A's part and B's part (and the caller's constraints, whose frame
//      numbers refer to the OUTPUT clip, before only_transition cuts it)
//      through run_constrained() of tasks/methods/jobs.h: every method that
//      fills gaps works, partial keys, targets, pins, a trajectory and
//      alternatives as for a constrained fill. The generated frames are
//      never read before (they hold A's pose at I).
//
// Automatic length (TransitionRequest::frames == 0): the time the body needs
// for the change, taken cheaply from the two seam frames (no solve):
//   - pose: the largest distance any joint moves between A's pose at I and
//     B's (placed) pose at J, both taken with the root at the origin and A's
//     facing, at kTransitionJointSpeed;
//   - ground (kKeep only; kAuto places B at the extrapolated distance): the
//     ground distance between the two seam roots at the mean of the two end
//     speeds, at least kTransitionMinGroundSpeed;
// the longer of the two, in frame steps at A's rate minus one (N frames make
// N + 1 steps), clamped to [10, 60] frames at 30 fps (scaled for other
// rates: [round(10 * fps / 30), round(60 * fps / 30)]). The chosen length is
// in the result and, when chosen automatically, in a warning sentence.
#pragma once

#include <string>
#include <vector>

#include "prior/motion/motion.h"
#include "tasks/constraints/constraint_spec.h"
#include "tasks/methods/jobs.h"

namespace mf {

/// Most generated frames a transition may ask for.
inline constexpr int kMaxTransitionFrames = 600;
/// Frame steps over which the seams' ground velocities are averaged.
inline constexpr int kTransitionVelocityFrames = 5;
/// The joint speed (m/s) the automatic length assumes for the pose change.
inline constexpr double kTransitionJointSpeed = 1.5;
/// The slowest ground speed (m/s) the automatic length assumes for covering
/// the distance between the seams (so standing clips far apart still walk).
inline constexpr double kTransitionMinGroundSpeed = 1.0;

/// What a transition asks for.
struct TransitionRequest {
  /// Generated frames N in [1, kMaxTransitionFrames]; 0 = automatic (see the
  /// top of this file).
  int frames = 0;
  /// A's last kept frame I; negative counts from A's end (-1 = A's last
  /// frame). A keeps at least two frames: I in [1, A's frames - 1].
  int from_frame = -1;
  /// B's first kept frame J; negative counts from B's end. B keeps at least
  /// two frames: J in [0, B's frames - 2].
  int to_frame = 0;
  enum class Placement { kAuto, kKeep };
  Placement place = Placement::kAuto;
  /// Return only the N generated frames (output frames I + 1 .. I + N; the
  /// seam frames A[I] and B[J] are not included) instead of the whole clip.
  bool only_transition = false;
  /// The caller's constraints (frames of the OUTPUT clip, joints of A's rig,
  /// positions in A's world and in `length_scale` units); the whole-pose
  /// keys of A's and B's parts are added to them.
  ConstraintSpec constraints;
  /// Metres per unit of the constraints' positions.
  double length_scale = 1.0;
};

/// What a transition gives: the solutions, their reports and warnings as
/// run_constrained() gives them (motions cut to the generated frames with
/// only_transition; reports measured on the whole clip), and where the
/// transition is.
struct TransitionResult : ConstrainedResult {
  int frames = 0;       ///< N, as asked or chosen
  int first_frame = 0;  ///< the first generated frame in the whole clip (I + 1)
  int from_frame = 0;   ///< I, resolved (non-negative)
  int to_frame = 0;     ///< J, resolved (non-negative)
};

/// `b` on the rig of `a` (see the top of this file, step 1): reordered by
/// name, or mapped by index when only the hierarchy agrees (a sentence saying
/// so appended to *warnings); InputError "clip B's rig differs from A's: ..."
/// otherwise. The result has `a`'s skeleton and `b`'s frames and rate.
Motion transition_onto_rig_of(const Motion& a, const Motion& b, std::vector<std::string>* warnings);

/// B (on A's rig and rate) placed to continue A's frame `from_frame` from its
/// frame `to_frame` after `frames` generated frames (Placement::kAuto, step 2
/// above).
Motion place_transition_clip(const Motion& a, const Motion& b, int from_frame, int to_frame, int frames);

/// The automatic length of a transition from A's frame `from_frame` to B's
/// (placed) frame `to_frame`, on one rig and rate (see the top of this file);
/// `ground` adds the ground term (Placement::kKeep).
int automatic_transition_frames(const Motion& a, const Motion& b, int from_frame, int to_frame, bool ground);

/// The transition of `a` into `b` with `method` (empty: the default method
/// for these constraints) and `alternatives` more solutions (0..16). Throws
/// InputError for clips of fewer than two frames, I or J out of range,
/// frames out of [0, kMaxTransitionFrames], rigs that do not match, and
/// whatever run_constrained() refuses; ModelMissingError and CancelledError
/// as every task.
TransitionResult run_transition(const Motion& a, const Motion& b, const TransitionRequest& request,
                                const std::string& method, int alternatives, const TaskContext& ctx = {});

}  // namespace mf
