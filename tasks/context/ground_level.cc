#include "tasks/context/ground_level.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "prior/motion/errors.h"

namespace mf {

std::vector<double> ground_heights(const Motion& motion, const std::vector<int>& known, const RigInfo& rig,
                                   int envelope_frames) {
  const int frames = motion.num_frames();
  std::vector<double> out(static_cast<size_t>(frames), 0.0);
  if (rig.foot_joints.empty() || known.empty()) return out;
  // Forward kinematics of the known frames only.
  Motion poses = Motion::identity(motion.skeleton, static_cast<int>(known.size()), motion.fps);
  for (size_t i = 0; i < known.size(); ++i) {
    const int f = known[i];
    if (f < 0 || f >= frames) throw InputError("ground_heights: known frame out of range");
    poses.root_positions[i] = motion.root_positions[f];
    for (int j = 0; j < motion.num_joints(); ++j) poses.rotation(static_cast<int>(i), j) = motion.rotation(f, j);
  }
  const GlobalPose g = forward_kinematics(poses);
  std::vector<double> lowest(known.size(), std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < known.size(); ++i)
    for (int k = 0; k < rig.num_feet(); ++k)
      lowest[i] = std::min(lowest[i], g.position(static_cast<int>(i), rig.foot_joints[k]).y() - rig.foot_heights[k]);
  std::vector<double> ground(known.size());
  for (size_t i = 0; i < known.size(); ++i) {
    ground[i] = lowest[i];
    for (size_t n = i; n > 0 && known[i] - known[n - 1] <= envelope_frames; --n)
      ground[i] = std::min(ground[i], lowest[n - 1]);
    for (size_t n = i + 1; n < known.size() && known[n] - known[i] <= envelope_frames; ++n)
      ground[i] = std::min(ground[i], lowest[n]);
  }
  for (int f = 0; f < frames; ++f) {
    const auto next = std::lower_bound(known.begin(), known.end(), f);
    if (next == known.begin()) {
      out[f] = ground.front();
    } else if (next == known.end()) {
      out[f] = ground.back();
    } else {
      const size_t b = static_cast<size_t>(next - known.begin()), a = b - 1;
      const double w = *next == known[a] ? 0.0 : double(f - known[a]) / double(*next - known[a]);
      out[f] = (1.0 - w) * ground[a] + w * ground[b];
    }
  }
  return out;
}

void shift_root_heights(Motion* motion, const std::vector<double>& heights, double sign) {
  if (static_cast<int>(heights.size()) != motion->num_frames())
    throw InputError("shift_root_heights: one height per frame is needed");
  for (int f = 0; f < motion->num_frames(); ++f) motion->root_positions[f].y() += sign * heights[f];
}

}  // namespace mf
