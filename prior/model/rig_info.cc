#include "prior/model/rig_info.h"

#include <algorithm>
#include <cctype>
#include <string>

#include "prior/motion/errors.h"
#include "prior/motion/motion.h"

namespace mf {
namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  size_t k = static_cast<size_t>(p * (v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

}  // namespace

std::vector<int> find_foot_joints(const Skeleton& skeleton, std::vector<bool>* toe_flags) {
  std::vector<int> ankles, toes;
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    std::string n = lower(skeleton.names[j]);
    if (n.find("toe") != std::string::npos) {
      toes.push_back(j);
    } else if (n.find("foot") != std::string::npos || n.find("ankle") != std::string::npos) {
      ankles.push_back(j);
    }
  }
  std::vector<int> feet = ankles;
  feet.insert(feet.end(), toes.begin(), toes.end());
  if (toe_flags) {
    toe_flags->assign(ankles.size(), false);
    toe_flags->insert(toe_flags->end(), toes.size(), true);
  }
  return feet;
}

RigInfo measure_rig(const Skeleton& skeleton, const std::vector<const Motion*>& clips) {
  RigInfo rig;
  rig.skeleton = skeleton;
  std::vector<bool> is_toe;
  rig.foot_joints = find_foot_joints(skeleton, &is_toe);

  // Forward axis: the signed root-local axis whose ground projection follows the velocity best.
  const Eigen::Vector3d axes[6] = {Eigen::Vector3d::UnitX(),  -Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                   -Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(),  -Eigen::Vector3d::UnitZ()};
  double score[6] = {0, 0, 0, 0, 0, 0};
  std::vector<std::vector<double>> per_clip_heights(rig.foot_joints.size());
  for (const Motion* m : clips) {
    const int T = m->num_frames();
    for (int f = 0; f + 1 < T; ++f) {
      Eigen::Vector3d v = (m->root_positions[f + 1] - m->root_positions[f]) * m->fps;
      v.y() = 0;
      if (v.norm() < 0.5) continue;
      v.normalize();
      for (int a = 0; a < 6; ++a) {
        Eigen::Vector3d d = m->rotation(f, 0) * axes[a];
        d.y() = 0;
        if (d.norm() > 1e-6) score[a] += d.normalized().dot(v);
      }
    }
    if (rig.foot_joints.empty()) continue;
    GlobalPose pose = forward_kinematics(*m);
    for (size_t k = 0; k < rig.foot_joints.size(); ++k) {
      std::vector<double> h(T);
      for (int f = 0; f < T; ++f) h[f] = pose.position(f, rig.foot_joints[k]).y();
      per_clip_heights[k].push_back(percentile(h, 0.05));
    }
  }
  int best = static_cast<int>(std::max_element(score, score + 6) - score);
  if (score[best] > 0) rig.root_forward = axes[best];
  for (size_t k = 0; k < rig.foot_joints.size(); ++k) {
    rig.foot_heights.push_back(percentile(per_clip_heights[k], 0.5));
    rig.foot_thresholds.push_back(is_toe[k] ? 0.04 : 0.08);
  }
  return rig;
}

void check_model_skeleton(const RigInfo& rig, const Skeleton& skeleton, const std::string& whose) {
  if (skeleton.num_joints() != rig.num_joints() || skeleton.names != rig.skeleton.names ||
      skeleton.parents != rig.skeleton.parents) {
    throw InputError("the " + whose + "'s skeleton does not match the model's: " +
                     std::to_string(skeleton.num_joints()) + " joints given, the model has " +
                     std::to_string(rig.num_joints()) + " (joint names and parents must agree)");
  }
}

}  // namespace mf
