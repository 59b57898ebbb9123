#include "tasks/latent/fallback.h"

#include <algorithm>
#include <sstream>

#include "prior/motion/rotations.h"

namespace mf {

double final_data_terms(const SolveSummary& summary) {
  double sum = 0.0;
  for (const auto& [name, value] : summary.final_terms) {
    if (name == "rotation" || name == "root_orientation" || name == "position" || name == "root_translation")
      sum += value;
  }
  return sum;
}

double key_motion_cm(const Motion& motion, const std::vector<int>& known) {
  if (motion.num_joints() == 0) return 0.0;
  const GlobalPose pose = forward_kinematics(motion);
  double sum = 0.0;
  int runs = 0;
  for (size_t i = 0; i + 1 < known.size(); ++i) {
    const int a = known[i], b = known[i + 1];
    if (b - a < 2) continue;
    double d = 0.0;
    for (int j = 0; j < motion.num_joints(); ++j) d += (pose.position(b, j) - pose.position(a, j)).norm();
    sum += 100.0 * d / motion.num_joints();
    ++runs;
  }
  return runs == 0 ? 0.0 : sum / runs;
}

WindowTrust judge_window(const InterpolationFallback& rule, const SolveSummary& summary, const Motion& window,
                         const std::vector<int>& known) {
  WindowTrust t;
  t.data_terms = final_data_terms(summary);
  t.key_motion_cm = key_motion_cm(window, known);
  t.interpolated = rule.enabled && (t.data_terms > rule.always_above ||
                                    (t.data_terms > rule.max_data_terms &&
                                     t.data_terms > rule.max_data_terms_per_cm * t.key_motion_cm));
  return t;
}

std::vector<double> interpolation_weights(const std::vector<WindowSpan>& spans, const std::vector<WindowTrust>& trust,
                                          int frames) {
  std::vector<double> sum(static_cast<size_t>(frames), 0.0), count(static_cast<size_t>(frames), 0.0);
  for (size_t k = 0; k < spans.size() && k < trust.size(); ++k) {
    const WindowSpan& s = spans[k];
    const double flag = trust[k].interpolated ? 1.0 : 0.0;
    for (int i = 0; i < s.length; ++i) {
      const int f = s.start + i;
      if (f < 0 || f >= frames) continue;
      // Over frames shared with windows solved before, this window's share
      // rises linearly away from them, as the WindowSolver's cross-fade does.
      double share = 1.0;
      if (i >= s.shared_begin && i < s.shared_end)
        share = double(i - s.shared_begin + 1) / double(s.shared_end - s.shared_begin + 1);
      sum[f] = sum[f] * (1.0 - share) + flag * share;
      count[f] = 1.0;
    }
  }
  for (int f = 0; f < frames; ++f)
    if (count[f] == 0.0) sum[f] = 0.0;
  return sum;
}

void blend_toward_interpolation(const Motion& interpolated, const std::vector<double>& weights, Motion* solved,
                                std::vector<float>* contacts) {
  const int frames = solved->num_frames(), joints = solved->num_joints();
  const size_t feet = frames > 0 && contacts ? contacts->size() / static_cast<size_t>(frames) : 0;
  for (int f = 0; f < frames; ++f) {
    const double w = weights[f];
    if (w <= 0.0) continue;
    for (int j = 0; j < joints; ++j)
      solved->rotation(f, j) = w >= 1.0 ? interpolated.rotation(f, j)
                                         : slerp(solved->rotation(f, j), interpolated.rotation(f, j), w);
    solved->root_positions[f] = w >= 1.0 ? interpolated.root_positions[f]
                                         : (1.0 - w) * solved->root_positions[f] + w * interpolated.root_positions[f];
    for (size_t c = 0; c < feet; ++c) (*contacts)[f * feet + c] *= static_cast<float>(1.0 - w);
  }
}

std::string fallback_note(const std::vector<WindowTrust>& trust, const InterpolationFallback& rule) {
  int n = 0;
  double worst = 0.0, motion = 0.0;
  for (const WindowTrust& t : trust) {
    if (!t.interpolated) continue;
    ++n;
    if (t.data_terms > worst) {
      worst = t.data_terms;
      motion = t.key_motion_cm;
    }
  }
  if (n == 0) return "";
  std::ostringstream s;
  s.precision(3);
  s << (n == static_cast<int>(trust.size()) ? "interpolation was used" :
        "interpolation was used in " + std::to_string(n) + " of " + std::to_string(trust.size()) + " windows")
    << ": the prior could not reach the keys (its fit to them " << worst << ", above " << rule.always_above
    << ", or above " << rule.max_data_terms << " and " << rule.max_data_terms_per_cm << " per cm of key motion, here "
    << motion << " cm), which on motion unlike its training data means interpolation is closer";
  return s.str();
}

}  // namespace mf
