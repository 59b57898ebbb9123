// Trajectories (MotionConstraints::trajectory, tasks/constraints/motion_constraints.h) as
// CSV text: the header "frame,x,z,forward_x,forward_z" (case and spaces
// ignored) as the first line, then one row per frame: the frame (a
// non-negative integer, strictly increasing from row to row), the root's
// ground position x, z in the input motion's own length unit (converted like
// every position of the constraints, ConstraintSpec::resolve()), and the
// facing direction forward_x, forward_z (any non-zero length; normalised when
// used). Blank lines, '#' comments and a UTF-8 byte order mark follow
// tasks/constraints/path_csv.h. Rows at frames whose root position a key fixes are
// allowed and ignored by the solvers (the known frames win). Bad input throws
// mf::InputError "<source>:<line>: ...".
#pragma once

#include <string>
#include <vector>

#include "tasks/constraints/motion_constraints.h"

namespace mf {

/// The header a trajectory CSV starts with.
inline constexpr const char* kTrajectoryCsvHeader = "frame,x,z,forward_x,forward_z";

/// Parses trajectory CSV text (see the top of this file); x and z stay in the
/// file's unit. Throws mf::InputError "<source>:<line>: ..." on a missing or
/// different header, a row without exactly five fields, a frame that is not a
/// non-negative integer, a frame not greater than the previous row's
/// (duplicate or decreasing), a non-finite value, a facing direction of zero
/// length (below 1e-6), more than kMaxPathFrames rows; "<source>: ..." when
/// there is no row.
std::vector<TrajectoryPoint> parse_trajectory_csv(const std::string& text, const std::string& source);
/// Reads a file (at most kMaxTextFileBytes, prior/util/binary_io.h) and parses
/// it; InputError "<path>: cannot open ..." if it cannot be read.
std::vector<TrajectoryPoint> read_trajectory_csv(const std::string& path);

}  // namespace mf
