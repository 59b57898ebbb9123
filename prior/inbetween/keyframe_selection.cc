#include "prior/inbetween/keyframe_selection.h"

#include <algorithm>
#include <vector>

namespace mf {

namespace {

// The picks between anchors a < b (frames) into `picked`, from the scores s.
void select_between(const float* s, int a, int b, int min_spacing, int max_spacing, bool* picked) {
  int prev = a;
  while (true) {
    const int lo = prev + min_spacing;
    const int hi = std::min(prev + max_spacing, b - min_spacing);
    if (lo > hi) return;
    int best = lo;
    for (int t = lo + 1; t <= hi; ++t) {
      if (s[t] >= s[best]) best = t;  // ties: the later frame (longer spacings)
    }
    const bool forced = b - prev > max_spacing;
    if (!forced && !(s[best] > 0.0f)) return;  // logit > 0: score above 0.5
    picked[best] = true;
    prev = best;
  }
}

}  // namespace

void select_window_keyframes(const float* logits, const bool* anchors, const bool* valid, int T, int min_spacing,
                             int max_spacing, bool* picked) {
  std::vector<int> points;
  for (int t = 0; t < T; ++t) {
    if (!valid[t]) continue;
    if (anchors[t] || points.empty()) points.push_back(t);
  }
  int last_valid = -1;
  for (int t = 0; t < T; ++t) {
    if (valid[t]) last_valid = t;
  }
  if (last_valid >= 0 && (points.empty() || points.back() != last_valid)) points.push_back(last_valid);
  for (size_t k = 0; k + 1 < points.size(); ++k) {
    select_between(logits, points[k], points[k + 1], min_spacing, max_spacing, picked);
  }
}

}  // namespace mf
