#include "tasks/constraints/interpolation_fill.h"

#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "tasks/constraints/residuals.h"

namespace mf {

namespace {

// Value at frame f of a series known at sorted `frames`: interpolated between
// the surrounding known frames, held before the first and after the last.
template <typename Lerp, typename Get>
auto interpolate_at(int f, const std::vector<int>& frames, Get get, Lerp lerp) {
  const ResidualBracket br = residual_bracket(f, frames, ResidualRamp::Linear);
  if (br.a == br.b) return get(frames[br.a]);
  return lerp(get(frames[br.a]), get(frames[br.b]), br.s);
}

}  // namespace

Motion fill_by_interpolation(const Motion& window, const MotionConstraints& constraints) {
  bool full = true;
  std::vector<int> frames;
  for (size_t k = 0; k < constraints.keys.size(); ++k) {
    full = full && constraints.keys[k].joints.empty() && constraints.keys[k].root_position &&
           constraints.keys[k].rotations;
    frames.push_back(constraints.keys[k].frame);
  }
  if (frames.empty()) throw InputError("interpolation needs at least one key");
  if (full) return interpolate_motion(window, frames);

  const int T = window.num_frames(), J = window.num_joints();
  Motion out = Motion::identity(window.skeleton, T, window.fps);
  for (int j = 0; j < J; ++j) {
    std::vector<int> known;
    for (size_t k = 0; k < constraints.keys.size(); ++k) {
      if (constraints.key_has_joint(k, j)) known.push_back(constraints.keys[k].frame);
    }
    if (known.empty()) continue;
    for (int f = 0; f < T; ++f) {
      out.rotation(f, j) = interpolate_at(
          f, known, [&](int g) { return window.rotation(g, j).normalized(); },
          [](const Eigen::Quaterniond& a, const Eigen::Quaterniond& b, double t) { return slerp(a, b, t); });
    }
  }
  std::vector<int> rooted;
  for (const PoseKey& k : constraints.keys) {
    if (k.root_position) rooted.push_back(k.frame);
  }
  if (!rooted.empty()) {
    for (int f = 0; f < T; ++f) {
      out.root_positions[f] = interpolate_at(
          f, rooted, [&](int g) { return window.root_positions[g]; },
          [](const Eigen::Vector3d& a, const Eigen::Vector3d& b, double t) -> Eigen::Vector3d {
            return a + (b - a) * t;
          });
    }
  }
  return out;
}

}  // namespace mf
