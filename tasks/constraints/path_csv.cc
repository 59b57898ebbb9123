#include "tasks/constraints/path_csv.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "prior/motion/errors.h"
#include "prior/util/binary_io.h"
#include "tasks/constraints/ground_path.h"

namespace mf {
namespace {

std::string trim(const std::string& s) {
  size_t b = 0, e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t' || s[b] == '\r')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t' || s[e - 1] == '\r')) --e;
  return s.substr(b, e - b);
}

}  // namespace

void for_each_csv_line(const std::string& text, const std::function<void(int, const std::string&)>& row) {
  size_t pos = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;  // UTF-8 BOM
  int line_no = 0;
  while (pos <= text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    const std::string line = trim(text.substr(pos, end - pos));
    pos = end + 1;
    ++line_no;
    if (!line.empty() && line[0] != '#') row(line_no, line);
  }
}

bool parse_csv_number(const std::string& field, double* out) {
  std::string f = trim(field);
  if (!f.empty() && f[0] == '+') f.erase(0, 1);
  if (f.empty()) return false;
  const char* b = f.data();
  const char* e = b + f.size();
  const auto r = std::from_chars(b, e, *out);
  return r.ec == std::errc() && r.ptr == e;
}

bool is_csv_header(const std::string& line, const std::string& header) {
  std::string compact;
  for (char c : line) {
    if (c != ' ' && c != '\t') compact += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return compact == header;
}

std::vector<Eigen::Vector2d> parse_path_csv(const std::string& text, const std::string& source) {
  std::vector<Eigen::Vector2d> out;
  bool first_content = true;
  for_each_csv_line(text, [&](int line_no, const std::string& line) {
    const bool header = first_content && is_csv_header(line, "x,z");
    first_content = false;
    if (header) return;
    const std::string where = source + ":" + std::to_string(line_no) + ": ";
    const size_t comma = line.find(',');
    if (comma == std::string::npos || line.find(',', comma + 1) != std::string::npos)
      throw InputError(where + "expected two comma-separated numbers x,z (metres), got '" + line + "'");
    double x = 0, z = 0;
    if (!parse_csv_number(line.substr(0, comma), &x) || !parse_csv_number(line.substr(comma + 1), &z))
      throw InputError(where + "expected two comma-separated numbers x,z (metres), got '" + line + "'");
    if (!std::isfinite(x) || !std::isfinite(z)) throw InputError(where + "non-finite value in '" + line + "'");
    if (out.size() >= static_cast<size_t>(kMaxPathFrames))
      throw InputError(where + "the path has more than " + std::to_string(kMaxPathFrames) + " points");
    out.emplace_back(x, z);
  });
  if (out.size() < 2)
    throw InputError(source + ": a path needs at least two points (x,z rows), got " + std::to_string(out.size()));
  return out;
}

std::vector<Eigen::Vector2d> read_path_csv(const std::string& path) {
  return parse_path_csv(read_file_limited(path, "path file", kMaxTextFileBytes), path);
}

}  // namespace mf
