#include "tasks/constraints/seams.h"

#include <algorithm>

namespace mf {

std::vector<RunSeam> run_seams(const GlobalPose& pose, const std::vector<int>& known) {
  std::vector<RunSeam> runs;
  const int J = pose.joints;
  if (J == 0) return runs;
  for (size_t i = 0; i + 1 < known.size(); ++i) {
    const int a = known[i], b = known[i + 1];
    if (b - a < 2) continue;
    double motion = 0.0, in = 0.0, out = 0.0;
    for (int j = 0; j < J; ++j) {
      const double d = (pose.position(b, j) - pose.position(a, j)).norm();
      motion += d;
      in += (pose.position(a + 1, j) - pose.position(a, j)).norm() - d / (b - a);
      out += (pose.position(b, j) - pose.position(b - 1, j)).norm() - d / (b - a);
    }
    runs.push_back({a, b, 100.0 * motion / J, std::max({0.0, 100.0 * in / J, 100.0 * out / J})});
  }
  return runs;
}

double seam_excess_cm(const Motion& result, const std::vector<int>& known) {
  double worst = 0.0;
  for (const RunSeam& r : run_seams(forward_kinematics(result), known)) worst = std::max(worst, r.seam_cm);
  return worst;
}

bool implausible_seam(const RunSeam& run) {
  return run.seam_cm > kMaxSeamCm || run.seam_cm > kMaxSeamShareOfKeyMotion * run.key_motion_cm;
}

}  // namespace mf
