#include "bench/op_profile.h"

#include <ATen/record_function.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "bench/text.h"

namespace mf::bench {
namespace {

using Clock = std::chrono::steady_clock;

struct Counts {
  std::map<std::string, std::pair<int64_t, double>> ops;  // name -> calls, outermost ms
  int depth = 0;
  Clock::time_point outer_start;
  bool active = false;
  at::CallbackHandle handle = 0;
};
Counts counts;

std::unique_ptr<at::ObserverContext> on_enter(const at::RecordFunction& fn) {
  auto& entry = counts.ops[fn.name()];
  ++entry.first;
  if (counts.depth++ == 0) counts.outer_start = Clock::now();
  return nullptr;
}

void on_exit(const at::RecordFunction& fn, at::ObserverContext*) {
  if (--counts.depth == 0) {
    counts.ops[fn.name()].second +=
        std::chrono::duration<double, std::milli>(Clock::now() - counts.outer_start).count();
  }
}

}  // namespace

OpProfile::OpProfile() {
  if (counts.active) throw std::logic_error("OpProfile: one profile at a time");
  counts = Counts{};
  counts.active = true;
  counts.handle = at::addThreadLocalCallback(
      at::RecordFunctionCallback(on_enter, on_exit)
          .scopes({at::RecordScope::FUNCTION, at::RecordScope::BACKWARD_FUNCTION})
          .needsInputs(false));
}

OpProfile::~OpProfile() {
  at::removeCallback(counts.handle);
  counts.active = false;
}

std::string OpProfile::table(double per, const std::string& per_name, int top) const {
  std::vector<std::pair<std::string, std::pair<int64_t, double>>> rows(counts.ops.begin(), counts.ops.end());
  std::sort(rows.begin(), rows.end(), [](const auto& a, const auto& b) { return a.second.second > b.second.second; });
  int64_t calls = 0;
  double ms = 0;
  for (const auto& r : rows) {
    calls += r.second.first;
    ms += r.second.second;
  }
  const double d = per > 0 ? per : 1;
  std::ostringstream s;
  s << "| operator | calls / " << per_name << " | outermost ms / " << per_name << " |\n|---|---:|---:|\n";
  for (int i = 0; i < static_cast<int>(rows.size()) && i < top; ++i) {
    s << "| `" << rows[i].first << "` | " << fixed(rows[i].second.first / d, 1) << " | "
      << fixed(rows[i].second.second / d, 3) << " |\n";
  }
  s << "| all " << rows.size() << " operators | " << fixed(calls / d, 1) << " | " << fixed(ms / d, 3) << " |\n";
  return s.str();
}

}  // namespace mf::bench
