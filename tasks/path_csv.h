// Ground paths (tasks/ground_path.h) as CSV text: one "x,z" pair per line,
// metres; an optional first line "x,z" (a header); blank lines and lines
// starting with '#' (after spaces) are skipped; a UTF-8 byte order mark is
// ignored; a third column is an error. Bad input throws mf::InputError naming
// the source and line.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace mf {

/// Parses path CSV text (see the top of this file) into (x, z) points, metres.
/// Throws mf::InputError "<source>:<line>: ..." on a malformed line (not two
/// comma-separated numbers, a third column, text after the numbers), on a
/// non-finite value, and "<source>: ..." when fewer than two points remain or
/// there are more than kMaxPathFrames. Does not check the path's length (see
/// validate_path()). Numbers are parsed independently of the locale.
std::vector<Eigen::Vector2d> parse_path_csv(const std::string& text, const std::string& source);
/// Reads a file and parses it; InputError "<path>: cannot open ..." if it cannot be read.
std::vector<Eigen::Vector2d> read_path_csv(const std::string& path);

}  // namespace mf
