// OpProfile: counts the ATen operators and autograd backward functions run on
// this thread while it is alive, and the wall time spent in the outermost ones
// (an operator called from inside another is counted but its time is its
// caller's). It shows where the framework's per-operation cost goes in a
// latent solve (docs/BENCHMARKS.md, "Where the time of a short solve goes").
// One profile at a time; the callback slows every operator a little, so the
// times are for ranking, not for the speed tables.
#pragma once

#include <cstdint>
#include <string>

namespace mf::bench {

class OpProfile {
 public:
  OpProfile();
  ~OpProfile();
  OpProfile(const OpProfile&) = delete;
  OpProfile& operator=(const OpProfile&) = delete;

  /// A markdown table of the `top` operators with the most outermost time: calls and
  /// outermost-call milliseconds, both divided by `per` (e.g. evaluations),
  /// and the totals.
  std::string table(double per, const std::string& per_name, int top = 25) const;
};

}  // namespace mf::bench
