#include "tasks/constraints/trajectory_csv.h"

#include <charconv>
#include <cmath>

#include "prior/motion/errors.h"
#include "prior/util/binary_io.h"
#include "tasks/constraints/ground_path.h"
#include "tasks/constraints/path_csv.h"

namespace mf {
namespace {

std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> fields;
  size_t b = 0;
  while (true) {
    const size_t c = line.find(',', b);
    fields.push_back(line.substr(b, c == std::string::npos ? std::string::npos : c - b));
    if (c == std::string::npos) return fields;
    b = c + 1;
  }
}

// A frame field: a non-negative integer that fits an int.
bool parse_frame(const std::string& field, int* out) {
  double v = 0;
  if (!parse_csv_number(field, &v) || !(v >= 0) || v > 2147483647.0 || v != std::floor(v)) return false;
  *out = static_cast<int>(v);
  return true;
}

TrajectoryPoint parse_row(const std::string& line, const std::string& where) {
  const std::vector<std::string> f = split_fields(line);
  if (f.size() != 5)
    throw InputError(where + "expected 5 comma-separated fields (" + kTrajectoryCsvHeader + "), got " +
                     std::to_string(f.size()) + " in '" + line + "'");
  TrajectoryPoint p;
  if (!parse_frame(f[0], &p.frame))
    throw InputError(where + "the frame must be a non-negative integer, got '" + f[0] + "'");
  double* values[4] = {&p.x, &p.z, &p.forward_x, &p.forward_z};
  static const char* names[4] = {"x", "z", "forward_x", "forward_z"};
  for (int i = 0; i < 4; ++i) {
    if (!parse_csv_number(f[i + 1], values[i]))
      throw InputError(where + "'" + names[i] + "' must be a number, got '" + f[i + 1] + "'");
    if (!std::isfinite(*values[i])) throw InputError(where + "non-finite value in '" + line + "'");
  }
  if (std::hypot(p.forward_x, p.forward_z) < 1e-6)
    throw InputError(where + "the facing direction (forward_x, forward_z) has zero length");
  return p;
}

}  // namespace

std::vector<TrajectoryPoint> parse_trajectory_csv(const std::string& text, const std::string& source) {
  std::vector<TrajectoryPoint> out;
  bool header = false;
  for_each_csv_line(text, [&](int line_no, const std::string& line) {
    const std::string where = source + ":" + std::to_string(line_no) + ": ";
    if (!header) {
      if (!is_csv_header(line, kTrajectoryCsvHeader))
        throw InputError(where + "expected the header '" + kTrajectoryCsvHeader + "', got '" + line + "'");
      header = true;
      return;
    }
    const TrajectoryPoint p = parse_row(line, where);
    if (!out.empty() && p.frame <= out.back().frame)
      throw InputError(where + "frame " + std::to_string(p.frame) +
                       (p.frame == out.back().frame ? " is given twice" : " comes after frame " + std::to_string(out.back().frame)) +
                       " (frames must be strictly increasing)");
    if (out.size() >= static_cast<size_t>(kMaxPathFrames))
      throw InputError(where + "the trajectory has more than " + std::to_string(kMaxPathFrames) + " rows");
    out.push_back(p);
  });
  if (!header) throw InputError(source + ": empty; a trajectory starts with the header '" + std::string(kTrajectoryCsvHeader) + "'");
  if (out.empty()) throw InputError(source + ": the trajectory has no rows");
  return out;
}

std::vector<TrajectoryPoint> read_trajectory_csv(const std::string& path) {
  return parse_trajectory_csv(read_file_limited(path, "trajectory file", kMaxTextFileBytes), path);
}

}  // namespace mf
