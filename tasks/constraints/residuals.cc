#include "tasks/constraints/residuals.h"

#include <algorithm>

#include "prior/motion/rotations.h"

namespace mf {

Eigen::Quaterniond rotation_residual(const Eigen::Quaterniond& given, const Eigen::Quaterniond& solution) {
  return (given.normalized() * solution.normalized().conjugate()).normalized();
}

void spread_rotation_residual(const Motion& given, const Motion& solution, int joint, const std::vector<int>& frames,
                              ResidualRamp ramp, Motion* out) {
  if (frames.empty()) return;
  std::vector<Eigen::Quaterniond> residual;
  residual.reserve(frames.size());
  for (int f : frames) residual.push_back(rotation_residual(given.rotation(f, joint), solution.rotation(f, joint)));
  size_t next = 0;
  for (int f = 0; f < out->num_frames(); ++f) {
    if (next < frames.size() && frames[next] == f) {
      out->rotation(f, joint) = given.rotation(f, joint);  // bit for bit
      ++next;
      continue;
    }
    const ResidualBracket br = residual_bracket(f, frames, ramp);
    const Eigen::Quaterniond r = slerp(residual[br.a], residual[br.b], br.s);
    out->rotation(f, joint) = (r * solution.rotation(f, joint).normalized()).normalized();
  }
}

void spread_root_residual(const Motion& given, const Motion& solution, const std::vector<int>& frames,
                          ResidualRamp ramp, Motion* out) {
  if (frames.empty()) return;
  std::vector<Eigen::Vector3d> residual;
  residual.reserve(frames.size());
  for (int f : frames) residual.push_back(given.root_positions[f] - solution.root_positions[f]);
  size_t next = 0;
  for (int f = 0; f < out->num_frames(); ++f) {
    if (next < frames.size() && frames[next] == f) {
      out->root_positions[f] = given.root_positions[f];
      ++next;
      continue;
    }
    const ResidualBracket br = residual_bracket(f, frames, ramp);
    out->root_positions[f] = solution.root_positions[f] + residual[br.a] * (1.0 - br.s) + residual[br.b] * br.s;
  }
}

}  // namespace mf
