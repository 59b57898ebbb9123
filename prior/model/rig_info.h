// What the prior knows about its rig beyond the skeleton, and how it is
// measured from clips: torch-free, shared by the model file's container
// (model_container.h), the libtorch prior (nemf.h) and the Eigen runtime
// (prior/runtime/).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "prior/motion/skeleton.h"

namespace mf {

struct Motion;

/// What the prior needs to know about a rig beyond its skeleton; measured from
/// the training data and stored in the model file.
struct RigInfo {
  Skeleton skeleton;
  Eigen::Vector3d root_forward{0, 0, 1};  ///< root-local axis that points forward
  std::vector<int> foot_joints;           ///< joints whose contacts the GMP predicts
  std::vector<double> foot_heights;       ///< standing height of each foot joint, metres
  std::vector<double> foot_thresholds;    ///< contact height threshold above standing height, metres
  double contact_speed = 0.25;            ///< max horizontal speed in contact, m/s

  int num_joints() const { return skeleton.num_joints(); }
  int num_feet() const { return static_cast<int>(foot_joints.size()); }
};

/// Foot joints of a skeleton by name (ankle: "foot"/"ankle", toe: "toe",
/// case-insensitive), ankles first; `toe_flags` (optional) tells which are toes.
std::vector<int> find_foot_joints(const Skeleton& skeleton, std::vector<bool>* toe_flags = nullptr);

/// Rig facts measured from clips: the root's forward axis (the root-local
/// principal axis best aligned with the horizontal velocity while moving), the
/// feet and their standing heights (median over clips of each clip's
/// 5th-percentile height), contact thresholds (ankle 8 cm, toe 4 cm above
/// standing height, as NeMF's, measured relative to this rig's standing height).
RigInfo measure_rig(const Skeleton& skeleton, const std::vector<const Motion*>& clips);

/// Throws mf::InputError "the <whose>'s skeleton does not match the model's:
/// ..." unless `skeleton` has the joints (names) and parents of `rig`'s.
void check_model_skeleton(const RigInfo& rig, const Skeleton& skeleton, const std::string& whose);

}  // namespace mf
