#include "prior/rig/mirror.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "prior/motion/errors.h"
#include "prior/rig/rig_map.h"

namespace mf {
namespace {

const Eigen::Matrix3d kWorldMirror = Eigen::Vector3d(-1.0, 1.0, 1.0).asDiagonal();

// The reflections a joint frame may need: one axis flipped, or all three.
std::array<Eigen::Matrix3d, 4> candidate_reflections() {
  return {Eigen::Matrix3d(Eigen::Vector3d(-1, 1, 1).asDiagonal()), Eigen::Matrix3d(Eigen::Vector3d(1, -1, 1).asDiagonal()),
          Eigen::Matrix3d(Eigen::Vector3d(1, 1, -1).asDiagonal()), Eigen::Matrix3d(-Eigen::Matrix3d::Identity())};
}

double angle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

struct Chooser {
  const Skeleton& s;
  const std::vector<int>& c;
  std::vector<Eigen::Matrix3d> mean;  // mean local rotation per joint
  std::vector<std::vector<int>> children;
  double tolerance;

  // How far S maps the counterparts' child offsets from the children's (max).
  double offset_gap(int j, const Eigen::Matrix3d& S) const {
    double worst = 0.0;
    for (int k : children[j]) worst = std::max(worst, (S * s.offsets[c[k]] - s.offsets[k]).norm());
    return worst;
  }
  bool fits(int j, const Eigen::Matrix3d& S) const {
    for (int k : children[j])
      if ((S * s.offsets[c[k]] - s.offsets[k]).norm() > tolerance + 0.05 * s.offsets[k].norm()) return false;
    return true;
  }
  // Mismatch of joint j's mirrored mean local rotation with its own, its
  // parent's frame reflected by Sp (the world mirror for the root).
  double own_cost(int j, const Eigen::Matrix3d& Sp, const Eigen::Matrix3d& S) const {
    return j == 0 ? 0.0 : angle(Sp * mean[c[j]] * S, mean[j]);
  }
  // The best own_cost of child k under a parent reflected by Sp.
  double best_child_cost(int k, const Eigen::Matrix3d& Sp) const {
    double best = std::numeric_limits<double>::infinity();
    for (const Eigen::Matrix3d& S : candidate_reflections())
      if (fits(k, S)) best = std::min(best, own_cost(k, Sp, S));
    return best;
  }
};

}  // namespace

std::vector<Eigen::Quaterniond> mean_local_rotations(const std::vector<const Motion*>& motions) {
  if (motions.empty()) throw InputError("mean_local_rotations: no motions");
  const int J = motions.front()->num_joints();
  std::vector<Eigen::Vector4d> sum(J, Eigen::Vector4d::Zero());
  for (const Motion* m : motions) {
    for (int f = 0; f < m->num_frames(); ++f)
      for (int j = 0; j < J; ++j) {
        const Eigen::Vector4d q = m->rotation(f, j).normalized().coeffs();
        const Eigen::Vector4d& ref = motions.front()->rotation(0, j).coeffs();
        sum[j] += q.dot(ref) < 0 ? -q : q;
      }
  }
  std::vector<Eigen::Quaterniond> mean(J);
  for (int j = 0; j < J; ++j) {
    mean[j].coeffs() = sum[j].norm() > 0 ? Eigen::Vector4d(sum[j].normalized()) : Eigen::Vector4d(0, 0, 0, 1);
  }
  return mean;
}

MirrorMap mirror_map(const Skeleton& skeleton, const std::vector<Eigen::Quaterniond>& mean_local, double tolerance) {
  const int J = skeleton.num_joints();
  if (static_cast<int>(mean_local.size()) != J) throw InputError("mirror_map: one mean rotation per joint is needed");
  MirrorMap map;
  map.counterpart = mirror_counterparts(skeleton);
  Chooser ch{skeleton, map.counterpart, {}, skeleton.children(), tolerance};
  for (const Eigen::Quaterniond& q : mean_local) ch.mean.push_back(q.normalized().toRotationMatrix());
  for (int j = 0; j < J; ++j) {
    const auto all = candidate_reflections();
    if (std::none_of(all.begin(), all.end(), [&](const Eigen::Matrix3d& S) { return ch.fits(j, S); })) {
      std::string kids;
      for (int k : ch.children[j]) kids += (kids.empty() ? "" : ", ") + skeleton.names[k];
      throw InputError("the rest offsets of the children of '" + skeleton.names[j] + "' (" + kids +
                       ") are not mirror images of their counterparts': the rig cannot be mirrored");
    }
  }
  map.reflection.resize(J);
  for (int j = 0; j < J; ++j) {  // parents come first
    const Eigen::Matrix3d Sp = j == 0 ? kWorldMirror : map.reflection[skeleton.parents[j]];
    double best = std::numeric_limits<double>::infinity();
    for (const Eigen::Matrix3d& S : candidate_reflections()) {
      if (!ch.fits(j, S)) continue;
      double cost = ch.own_cost(j, Sp, S);
      for (int k : ch.children[j]) cost += ch.best_child_cost(k, S);
      if (cost < best) best = cost, map.reflection[j] = S;
    }
    map.max_asymmetry = std::max(map.max_asymmetry, ch.offset_gap(j, map.reflection[j]));
  }
  return map;
}

Motion mirror_motion(const Motion& motion, const MirrorMap& map) {
  const int J = motion.num_joints();
  if (static_cast<int>(map.counterpart.size()) != J || static_cast<int>(map.reflection.size()) != J)
    throw InputError("mirror_motion: the mirror map is for another skeleton");
  Motion out = motion;
  for (int f = 0; f < motion.num_frames(); ++f) {
    out.root_positions[f] = kWorldMirror * motion.root_positions[f];
    for (int j = 0; j < J; ++j) {
      const Eigen::Matrix3d& Sp = j == 0 ? kWorldMirror : map.reflection[motion.skeleton.parents[j]];
      const Eigen::Matrix3d R = motion.rotation(f, map.counterpart[j]).normalized().toRotationMatrix();
      out.rotation(f, j) = Eigen::Quaterniond(Eigen::Matrix3d(Sp * R * map.reflection[j]));
    }
  }
  return out;
}

}  // namespace mf
