// Rig maps: which joint of a user's humanoid skeleton plays which part of
// another skeleton (the model's), found from joint names and the hierarchy's
// shape, or given by a small JSON map file.
//
// A humanoid is described by its *parts*: the hips, a spine chain of any length,
// the chest (the spine joint where both arms branch off), an optional neck, the
// head, and per side an optional shoulder (clavicle), upper arm, forearm and hand,
// thigh, shin, foot and an optional toe. Required: hips, chest, head and every
// arm and leg joint except shoulders and toes.
//
// Names are compared with case, separators (space _ . -) and any namespace
// prefix ("mixamorig:", "Armature|") ignored; the side comes from a "left"/"right"
// word or an l/r token at either end ("LeftArm", "Arm_L", "arm.l", "L_Elbow",
// "LHipJoint", "Bip01 L Thigh"). The naming table (docs/RIGS.md) covers Mixamo
// (with and without "mixamorig:"), CMU/MotionBuilder, Ubisoft LaFAN1, the Unreal
// mannequin, Blender Rigify/metarig (DEF-/ORG- prefixes, .L/.R), SMPL and the
// Bandai Namco rig of the training data. Where names do not say which joint of
// a limb is which, the limb chain's joints with the longest bones are taken in
// order (thigh, shin, foot, toe; shoulder, upper arm, forearm, hand); twist and
// roll helpers and zero-length joints are skipped.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "prior/motion/skeleton.h"

namespace mf {

/// The joints of one side's limbs; -1 where absent.
struct ArmParts {
  int shoulder = -1, upper = -1, fore = -1, hand = -1;
  /// No hand joint: the forearm is the chain's last joint and the wrist is
  /// its BVH End Site (rigs without hands, such as ReActIdle's). The
  /// retargeter then takes the forearm to continue the upper arm in the rest
  /// pose (a straight elbow there, as in T and A poses).
  bool hand_is_end = false;
};
struct LegParts {
  int thigh = -1, shin = -1, foot = -1, toe = -1;
};

/// The humanoid parts of one skeleton (joint indices, -1 where absent).
struct RigParts {
  int hips = -1;
  std::vector<int> spine;  ///< joints strictly between hips and chest, hips side first
  int chest = -1;
  int neck = -1;
  int head = -1;
  std::array<ArmParts, 2> arms;  ///< [0] left, [1] right
  std::array<LegParts, 2> legs;  ///< [0] left, [1] right

  /// Names of the required parts that are missing ("hips", "left forearm", ...).
  std::vector<std::string> missing() const;
  /// "part" name of joint j ("hips", "spine 2", "left hand", ...), or "" if it plays none.
  std::string part_of(int joint) const;
  /// Every (part name, joint) pair that is set, in a fixed order.
  std::vector<std::pair<std::string, int>> list() const;
};

/// Finds the parts of `skeleton` from its names and shape. Never throws on a
/// non-humanoid: parts it cannot find stay -1 (check missing()).
RigParts find_rig_parts(const Skeleton& skeleton);

/// "left"/"right" side of a joint name (0 / 1), or -1 when the name has none.
int name_side(const std::string& name);

/// Each joint's left/right counterpart by name ("LeftArm" <-> "RightArm",
/// "hand_l" <-> "hand_r": the same words with the other side), the joint
/// itself for names without a side. Throws mf::InputError naming a sided
/// joint without a counterpart, or a counterpart on another side of the
/// hierarchy (its parent's counterpart is not its parent).
std::vector<int> mirror_counterparts(const Skeleton& skeleton);

/// The correspondence between a user's skeleton and the model's.
struct RigMap {
  /// For every model joint: the user joint that plays it, or -1 (the
  /// retargeter then places it between its mapped neighbours).
  std::vector<int> user_of_model;
  RigParts user_parts;   ///< the user's parts, as the map assigns them
  RigParts model_parts;  ///< the model's parts
  /// How each model joint's user joint was found: "name", "shape" or "map file".
  std::vector<std::string> how;

  /// The map as JSON text: {"user joint": "model joint", ...} in model joint order.
  std::string to_json(const Skeleton& user, const Skeleton& model) const;
};

/// Maps `user` onto `model`: both skeletons' parts are found (find_rig_parts),
/// then matched part by part (spine chains by their ends: the first spine joint
/// to the first, the chest to the chest; extra chain joints stay unmapped).
/// `map_json` (may be empty) overrides: a JSON object {"user joint": "model
/// joint" or null (unmap), ...}. Throws InputError when the JSON is malformed,
/// names a joint that does not exist on either side, maps one user joint twice
/// (a duplicate key) or two user joints onto one model joint, or when a required
/// part of the model is left without a user joint: the message lists the parts
/// found (with their joints) and the ones missing.
RigMap map_rig(const Skeleton& user, const Skeleton& model, const std::string& map_json = "");

/// Reads a map file for map_rig (errors name the file).
std::string read_rig_map_file(const std::string& path);

}  // namespace mf
