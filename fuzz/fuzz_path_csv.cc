// Fuzz target: the path CSV reader (tasks/constraints/path_csv.h) on any bytes.
// Contract checked: bad input throws mf::InputError naming the source; a path
// that parses has at least two points, all finite.
#include <cmath>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_check.h"
#include "prior/motion/errors.h"
#include "tasks/constraints/path_csv.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const std::vector<Eigen::Vector2d> path = mf::parse_path_csv(text, "in.csv");
    MF_FUZZ_CHECK(path.size() >= 2);
    for (const Eigen::Vector2d& p : path) MF_FUZZ_CHECK(std::isfinite(p.x()) && std::isfinite(p.y()));
  } catch (const mf::InputError& e) {
    MF_FUZZ_CHECK(std::string(e.what()).rfind("in.csv", 0) == 0);
  }
  return 0;
}
