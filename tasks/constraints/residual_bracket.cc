#include "tasks/constraints/residual_bracket.h"

#include <algorithm>
#include <utility>

namespace mf {

double smoothstep(double t) { return t * t * (3.0 - 2.0 * t); }

ResidualBracket residual_bracket(int f, const std::vector<int>& frames, ResidualRamp ramp) {
  const auto it = std::lower_bound(frames.begin(), frames.end(), f);
  if (it == frames.end()) return {frames.size() - 1, frames.size() - 1, 0.0};
  const size_t b = static_cast<size_t>(it - frames.begin());
  if (*it == f || b == 0) return {b, b, 0.0};
  const double u = static_cast<double>(f - frames[b - 1]) / (frames[b] - frames[b - 1]);
  return {b - 1, b, ramp == ResidualRamp::Smoothstep ? smoothstep(u) : u};
}

void key_brackets(const std::vector<int>& key_frames, const std::vector<char>& on, int length,
                  std::vector<KeyBracket>* out) {
  std::vector<std::pair<int, int>> keys;  // (frame, key index)
  for (size_t k = 0; k < on.size(); ++k) {
    if (on[k]) keys.emplace_back(key_frames[k], static_cast<int>(k));
  }
  std::sort(keys.begin(), keys.end());
  std::vector<int> frames;
  for (const auto& k : keys) frames.push_back(k.first);
  out->assign(length, KeyBracket{});
  if (keys.empty()) return;
  for (int f = 0; f < length; ++f) {
    const ResidualBracket br = residual_bracket(f, frames, ResidualRamp::Smoothstep);
    (*out)[f] = {keys[br.a].second, keys[br.b].second, static_cast<float>(br.s), true};
  }
}

}  // namespace mf
