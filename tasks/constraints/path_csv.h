// Ground paths (tasks/constraints/ground_path.h) as CSV text: one "x,z" pair per line,
// metres; an optional first line "x,z" (a header); blank lines and lines
// starting with '#' (after spaces) are skipped; a UTF-8 byte order mark is
// ignored; a third column is an error. Bad input throws mf::InputError naming
// the source and line.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

namespace mf {

/// The CSV conventions shared by the path and trajectory files: calls
/// `row(line_number, line)` (1-based, the line trimmed of spaces, tabs and
/// '\r') for every line of `text` that is neither blank nor a comment (first
/// non-space character '#'), after a UTF-8 byte order mark.
void for_each_csv_line(const std::string& text, const std::function<void(int, const std::string&)>& row);
/// One CSV field as a number (spaces around it and a leading '+' allowed),
/// locale-independent; false unless the whole field is one number.
bool parse_csv_number(const std::string& field, double* out);
/// A header line compared case-insensitively without spaces and tabs: true
/// when `line` is `header` (e.g. "x,z").
bool is_csv_header(const std::string& line, const std::string& header);

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
