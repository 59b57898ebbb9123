#include "bench/text.h"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "prior/motion/errors.h"

namespace mf::bench {

std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  if (out.empty()) throw InputError("empty list '" + s + "'");
  return out;
}

std::vector<int> int_list(const std::string& s) {
  std::vector<int> out;
  for (const std::string& x : split_list(s)) {
    char* end = nullptr;
    errno = 0;
    const long v = std::strtol(x.c_str(), &end, 10);
    if (*end != '\0' || errno != 0 || v < -1000000 || v > 1000000) {
      throw InputError("'" + x + "' in '" + s + "' is not an integer");
    }
    out.push_back(static_cast<int>(v));
  }
  return out;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace mf::bench
