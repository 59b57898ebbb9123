#include "tasks/constraints/ground_path.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "prior/motion/errors.h"

namespace mf {
namespace {

std::string fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

double path_length(const std::vector<Eigen::Vector2d>& path) {
  double L = 0.0;
  for (size_t i = 1; i < path.size(); ++i) L += (path[i] - path[i - 1]).norm();
  return L;
}

void validate_path(const std::vector<Eigen::Vector2d>& path) {
  if (path.size() < 2)
    throw InputError("a path needs at least two points, got " + std::to_string(path.size()));
  if (path.size() > static_cast<size_t>(kMaxPathFrames))
    throw InputError("the path has more than " + std::to_string(kMaxPathFrames) + " points");
  for (size_t i = 0; i < path.size(); ++i) {
    if (!path[i].allFinite()) throw InputError("path point " + std::to_string(i) + " is not finite");
  }
  if (path_length(path) < 1e-3)
    throw InputError("the path has zero length: its points are all the same (at least 1 mm of travel is needed)");
}

double mean_ground_speed(const Motion& motion) {
  const int N = motion.num_frames();
  if (N < 2 || !(motion.fps > 0)) return 0.0;
  double L = 0.0;
  for (int f = 1; f < N; ++f) {
    const Eigen::Vector3d d = motion.root_positions[f] - motion.root_positions[f - 1];
    L += std::hypot(d.x(), d.z());
  }
  return L / ((N - 1) / motion.fps);
}

int polyline_frame_count(const std::vector<Eigen::Vector2d>& vertices, double speed, double fps) {
  validate_path(vertices);
  if (!(std::isfinite(fps) && fps > 0)) throw InputError("the path's frame rate must be finite and positive");
  if (!std::isfinite(speed) || speed < 0.01)
    throw InputError("the reference barely moves (mean ground speed " + fmt(speed) +
                     " m/s): give the polyline's frame count explicitly");
  const double frames = std::round(path_length(vertices) / speed * fps) + 1.0;
  if (frames > kMaxPathFrames)
    throw InputError("the polyline would take more than " + std::to_string(kMaxPathFrames) + " frames");
  return std::max(2, static_cast<int>(frames));
}

std::vector<Eigen::Vector2d> resample_polyline(const std::vector<Eigen::Vector2d>& vertices, int frames) {
  validate_path(vertices);
  if (frames < 2 || frames > kMaxPathFrames)
    throw InputError("a resampled path needs 2 to " + std::to_string(kMaxPathFrames) + " frames, not " +
                     std::to_string(frames));
  std::vector<double> cum(vertices.size(), 0.0);
  for (size_t i = 1; i < vertices.size(); ++i) cum[i] = cum[i - 1] + (vertices[i] - vertices[i - 1]).norm();
  const double L = cum.back();
  std::vector<Eigen::Vector2d> out(frames);
  size_t seg = 1;
  for (int i = 0; i < frames; ++i) {
    if (i == frames - 1) {
      out[i] = vertices.back();
      break;
    }
    const double s = L * i / (frames - 1);
    while (seg + 1 < vertices.size() && cum[seg] < s) ++seg;
    const double len = cum[seg] - cum[seg - 1];
    const double t = len > 0 ? std::clamp((s - cum[seg - 1]) / len, 0.0, 1.0) : 0.0;
    out[i] = vertices[seg - 1] + (vertices[seg] - vertices[seg - 1]) * t;
  }
  return out;
}

std::vector<double> tangent_yaws(const std::vector<Eigen::Vector2d>& p, const std::vector<double>& fallback) {
  const int N = static_cast<int>(p.size());
  constexpr int k = 2;
  constexpr double eps = 1e-3;
  std::vector<double> yaw(N, 0.0);
  std::vector<char> valid(N, 0);
  for (int f = 0; f < N; ++f) {
    const Eigen::Vector2d d = p[std::min(N - 1, f + k)] - p[std::max(0, f - k)];
    if (d.norm() >= eps) {
      yaw[f] = std::atan2(d.x(), d.y());
      valid[f] = 1;
    }
  }
  // Where no tangent is defined, hold the nearest valid one (the earlier on a tie).
  std::vector<int> left(N, -1), right(N, -1);
  for (int f = 0, last = -1; f < N; ++f) {
    if (valid[f]) last = f;
    left[f] = last;
  }
  for (int f = N - 1, next = -1; f >= 0; --f) {
    if (valid[f]) next = f;
    right[f] = next;
  }
  if (left[N - 1] < 0) {
    for (int f = 0; f < N; ++f) yaw[f] = fallback.size() == static_cast<size_t>(N) ? fallback[f] : 0.0;
    return yaw;
  }
  std::vector<double> held(yaw);
  for (int f = 0; f < N; ++f) {
    if (valid[f]) continue;
    const int a = left[f], b = right[f];
    held[f] = (a >= 0 && (b < 0 || f - a <= b - f)) ? yaw[a] : yaw[b];
  }
  return held;
}

}  // namespace mf
