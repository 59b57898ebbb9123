#include "bench/text.h"

#include <cstdio>
#include <fstream>
#include <iostream>

namespace mf::bench {

std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void stream_gap_table(const std::string& head, const std::vector<int>& gaps,
                      const std::function<std::string(int)>& rows, const std::string& out) {
  std::string md = head;
  std::cout << head << std::flush;
  for (int T : gaps) {
    const std::string text = rows(T);
    std::cout << text << std::flush;
    md += text;
  }
  if (!out.empty()) std::ofstream(out) << md;
}

}  // namespace mf::bench
