// What the prior knows about its rig beyond the skeleton: torch-free, shared by
// the model file's container (model_container.h), the libtorch prior (nemf.h)
// and the Eigen runtime (prior/runtime/).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "prior/motion/skeleton.h"

namespace mf {

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

}  // namespace mf
