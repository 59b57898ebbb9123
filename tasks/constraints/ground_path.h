// Ground paths: where a character should walk, as a list of (x, z) points in
// metres, world frame (Y up, prior/motion/skeleton.h). Re-navigation
// (tasks/renav/renav.h) takes one point per output frame; a polyline (a few
// vertices) becomes one by resample_polyline(). Text files of paths:
// tasks/constraints/path_csv.h.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "prior/motion/motion.h"

namespace mf {

/// Longest path accepted (points per frame, or frames of a resampled polyline).
constexpr int kMaxPathFrames = 1'000'000;

/// Throws mf::InputError unless the path has at least two points, at most
/// kMaxPathFrames, every value finite, and a total length (sum of the
/// distances between consecutive points) of at least 1 mm.
void validate_path(const std::vector<Eigen::Vector2d>& path);

/// Total length of a polyline, metres.
double path_length(const std::vector<Eigen::Vector2d>& path);

/// Mean horizontal root speed of a motion (m/s): the summed ground distance
/// between consecutive root positions over the duration. 0 for one frame.
double mean_ground_speed(const Motion& motion);

/// Frames of a polyline walked at `speed` (m/s) and `fps`:
/// round(length / speed * fps) + 1, at least 2. Throws mf::InputError if the
/// speed is below 1 cm/s (the reference barely moves: give a frame count),
/// fps or speed are not finite and positive, or the result exceeds
/// kMaxPathFrames.
int polyline_frame_count(const std::vector<Eigen::Vector2d>& vertices, double speed, double fps);

/// `frames` (>= 2) points at equal arc-length spacing along the polyline
/// `vertices` (validated with validate_path()): point i at arc length
/// L * i / (frames - 1); the first and last points are the first and last
/// vertices. Zero-length segments (repeated vertices) are skipped.
std::vector<Eigen::Vector2d> resample_polyline(const std::vector<Eigen::Vector2d>& vertices, int frames);

/// Yaw (radians, atan2(dx, dz): 0 = +Z, the heading convention of
/// representation.h) of the ground tangent of `points` at every point: the
/// direction of p(i + 2) - p(i - 2) (indices clamped at the ends); where that
/// is shorter than 1 mm the nearest valid tangent is held (the earlier on a
/// tie); `fallback` (one value per point, or empty for 0) where no point of
/// the path moves.
std::vector<double> tangent_yaws(const std::vector<Eigen::Vector2d>& points, const std::vector<double>& fallback = {});

}  // namespace mf
