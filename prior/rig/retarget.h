// Retargeting between a user's humanoid rig and the model's, both ways, without
// assuming the rigs share rest poses, local axes, bone lengths or units.
//
// Every mapped joint gets an *anatomical frame*: a rotation fixed in the joint's
// own local frame whose first axis follows the body part (hips -> chest, upper
// arm -> forearm, shin -> foot, ...) and whose second axis is an anatomical
// direction measured from joint positions (the knee's or elbow's hinge axis,
// the line between the thighs or the shoulders). Both are averaged over the
// frames of a motion on that rig (estimate_anatomy), so T-pose, A-pose and
// "collapsed" rests (every bone along local X, as in the training data and in
// LaFAN1) and arbitrarily rotated local frames all give the same anatomy.
// Transfer keeps the world anatomical frames equal:
//   G_model(t) * A_model = G_user(t) * A_user,
// so directions and twist of every mapped part follow exactly, relative to each
// rig's own anatomy. Joints of one rig that lie between mapped joints of the
// other (spine chains of other lengths, twist bones, clavicles) get the
// interpolation of their neighbours' world anatomical frames by arc length.
// The root path is scaled by the ratio of leg lengths.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <string>
#include <vector>

#include "prior/motion/motion.h"
#include "prior/rig/rig_map.h"

namespace mf {

/// The anatomical frames of one rig, estimated from motion on it.
struct RigAnatomy {
  /// Per joint: the anatomical frame in the joint's local frame (identity for
  /// joints that play no part). `toe_frames`: the feet's frames measured along
  /// the toes (used when both rigs have toes; identity elsewhere).
  std::vector<Eigen::Quaterniond> frames;
  std::vector<Eigen::Quaterniond> toe_frames;
  /// Per joint: the mean local rotation over the frames read (a natural pose for
  /// joints the other rig lacks, e.g. the toes).
  std::vector<Eigen::Quaterniond> mean_local;
  /// Thigh to ankle, averaged over both legs, metres.
  double leg_length = 0.0;
  /// Per joint (or empty: none measured): unit directions of the rotation
  /// vector of mean_local^-1 * local (the joint's local frame) along which the
  /// rig's motion does not turn that joint: two for a hinge such as the
  /// training data's knees and toes, one for a joint with two degrees of
  /// freedom. From measure_locked_axes() on a large motion set, never from a
  /// user's few frames; motion retargeted onto this rig is kept off them.
  std::vector<std::vector<Eigen::Vector3d>> locked_axes;

  /// JSON with per-joint quaternions (w, x, y, z) keyed by joint name.
  std::string to_json(const Skeleton& skeleton) const;
  /// Inverse of to_json; throws InputError if a joint of `skeleton` is missing
  /// or a value is malformed.
  static RigAnatomy from_json(const std::string& text, const Skeleton& skeleton, const std::string& source);
};

/// Estimates the anatomy of `motion`'s rig from the frames listed in `frames`
/// (all frames when empty; no other frame is read). `parts` from
/// find_rig_parts() or RigMap. Throws InputError if a required part is missing.
RigAnatomy estimate_anatomy(const Motion& motion, const RigParts& parts, const std::vector<int>& frames = {});

/// When `skeleton`'s rest pose (every local rotation identity) is a T or A
/// pose (standing along an axis of the file, legs down, straight arms out to
/// the sides at most 60 degrees below horizontal), replaces the anatomical
/// frames (`frames`, `toe_frames`) of `anatomy` by that pose's, in the
/// conventions of reference_pose(): torso and head along the axis, the knees'
/// hinges along the line between the thighs, the elbows' vertical to the arm
/// and the facing direction, first axes along the bones. Returns true then;
/// false (nothing changed) for any other rest. The rest pose is one pose the
/// rig's author chose, where a few frames of motion mix the clip's poses into
/// the frames (docs/RIGS.md).
///
/// `keep_elbow_frames[side]`: that arm's joints whose second axis is the
/// elbow's hinge (upper arm, forearm, hand and the joints between them) keep
/// their frames. A T or A pose does not tell the elbow's hinge (palms down or
/// forward look the same from the joints' positions), so real rigs need it
/// measured from bent elbows (mean_elbow_bend()).
bool take_rest_pose_frames(const Skeleton& skeleton, const RigParts& parts, RigAnatomy* anatomy,
                           std::array<bool, 2> keep_elbow_frames = {false, false});

/// Per arm (left, right), the mean over `frames` (all when empty) of the sine
/// of the elbow's bend, from the joints' positions: how much estimate_anatomy()
/// can measure of that elbow's hinge.
std::array<double, 2> mean_elbow_bend(const Motion& motion, const RigParts& parts, const std::vector<int>& frames = {});
/// Whether take_rest_pose_frames reads `skeleton`'s rest pose (a T or A pose).
bool rest_pose_is_t_or_a(const Skeleton& skeleton, const RigParts& parts);

/// The anatomy of a user's rig for retargeting its motion: estimate_anatomy()
/// on the frames `frames` (all when empty), then the rest pose's frames when
/// it is a T or A pose (take_rest_pose_frames()), except for an arm whose
/// elbow is bent on average by more than about 9 degrees in those frames
/// (mean_elbow_bend() at least 0.15) and whose measured hinge differs from
/// the rest pose's by more than kElbowConventionDegrees: the rest pose then
/// has another elbow convention than the joints' positions show (CMU's
/// T-pose: 26-47 degrees on the foreign capture), and the measured hinge is
/// kept; a smaller difference is the few frames' noise (T-pose rigs built on
/// the training rig's anatomy: median 7.5, 90th percentile 21 degrees), and
/// the rest pose's exact hinge wins (docs/RIGS.md).
inline constexpr double kElbowConventionDegrees = 25.0;
RigAnatomy user_rig_anatomy(const Motion& motion, const RigParts& parts, const std::vector<int>& frames = {});

/// Fills anatomy->locked_axes from `motion` (mean_local must be set, e.g. by
/// estimate_anatomy on the same motion): per joint, the principal directions
/// of its local rotations about mean_local whose standard deviation is below
/// `max_sd_degrees`. Joints that hardly move at all (every direction below it,
/// e.g. a container root) get none.
void measure_locked_axes(const Motion& motion, double max_sd_degrees, RigAnatomy* anatomy);

/// `local` (a local rotation of `joint` on the rig of `anatomy`) with its
/// rotation about the joint's locked axes removed: the nearest rotation the
/// rig's own motion makes. `local` itself when the joint has none.
Eigen::Quaterniond without_locked_rotation(const RigAnatomy& anatomy, int joint, const Eigen::Quaterniond& local);

/// Leg length (thigh to ankle, mean of both legs) of a skeleton's rest offsets,
/// in the skeleton's units; 0 when the legs are not found.
double leg_length(const Skeleton& skeleton, const RigParts& parts);

/// World rotations of every joint in a T-pose (arm_down_degrees = 0) or an
/// A-pose (arms lowered by that angle) of a rig facing +Z with Y up, built from
/// its anatomy: spine, neck and head up, legs down, feet and toes forward, arms
/// out to the sides with the elbows' hinges vertical. Joints that play no part
/// take their mean local rotation under their parent.
std::vector<Eigen::Quaterniond> reference_pose(const Skeleton& skeleton, const RigParts& parts,
                                               const RigAnatomy& anatomy, double arm_down_degrees = 0.0);

class Retargeter {
 public:
  /// `map` from map_rig(user, model); anatomies of both rigs.
  Retargeter(Skeleton user, Skeleton model, RigMap map, RigAnatomy user_anatomy, RigAnatomy model_anatomy);

  /// The user's motion on the model's rig: same frames and fps.
  Motion to_model(const Motion& user) const;
  /// A model-rig motion back on the user's rig. `reference`, on the user's rig
  /// with the same frame count and fps, supplies what the model does not have
  /// (joints the map leaves out: fingers, props, helpers above the hips) and
  /// the part of each pose the round trip does not carry: the result is
  ///   reference_local * raw(to_model(reference))_local^-1 * raw(model)_local
  /// per joint (the root position likewise by differences), so with
  /// model == to_model(reference) the result equals `reference`.
  Motion to_user(const Motion& model, const Motion& reference) const;

  /// Model metres per user metre (leg length ratio).
  double scale() const { return scale_; }
  const RigMap& map() const { return map_; }

 private:
  // World anatomical frames -> local rotations on a rig, for the joints `set`.
  Motion transfer(const Motion& src, bool to_model, const Motion* reference) const;
  /// For each joint of the destination rig, its source joint (-1: none).
  std::vector<int> source_joints(bool to_model) const;
  /// The anatomical frame of joint j the transfer uses: a foot's toe frame
  /// when both rigs have toes.
  const Eigen::Quaterniond& joint_frame(const RigAnatomy& anatomy, const RigParts& parts, int j) const;

  Skeleton user_, model_;
  RigMap map_;
  RigAnatomy user_anatomy_, model_anatomy_;
  bool toes_ = false;
  double scale_ = 1.0;
};

}  // namespace mf
