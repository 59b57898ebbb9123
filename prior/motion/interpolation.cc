#include "prior/motion/interpolation.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"

namespace mf {
namespace {

// Cheap structural checks so that a caller who skipped tasks/methods/jobs.h gets an
// InputError instead of an out-of-bounds read.
void check_shape(const Motion& input) {
  const size_t frames = input.root_positions.size();
  if (input.rotations.size() != frames * static_cast<size_t>(input.num_joints()))
    throw InputError("motion has " + std::to_string(input.rotations.size()) + " rotations, expected " +
                     std::to_string(frames) + " frames x " + std::to_string(input.num_joints()) + " joints");
  if (!(std::isfinite(input.fps) && input.fps > 0)) throw InputError("motion fps must be finite and positive");
}

void check_known(const std::vector<int>& known, int frames) {
  if (known.empty()) throw InputError("at least one known frame is required");
  for (size_t i = 0; i < known.size(); ++i) {
    if (known[i] < 0 || known[i] >= frames)
      throw InputError("known frame " + std::to_string(known[i]) + " is out of range [0, " + std::to_string(frames) + ")");
    if (i > 0 && known[i] <= known[i - 1]) throw InputError("known frames must be strictly increasing");
  }
}

void check_resample(const Motion& input, double new_fps, int frames) {
  check_shape(input);
  if (input.num_frames() < 1) throw InputError("cannot resample a motion without frames");
  if (!(std::isfinite(new_fps) && new_fps > 0)) throw InputError("target fps must be finite and positive");
  if (frames < 1) throw InputError("output frame count must be at least 1");
}

void copy_frame(const Motion& from, int f_from, Motion& to, int f_to) {
  const int J = from.num_joints();
  to.root_positions[f_to] = from.root_positions[f_from];
  for (int j = 0; j < J; ++j) to.rotation(f_to, j) = from.rotation(f_from, j);
}

// Frame f_to of `to` = interpolation between frames a and b of `from` at t in (0, 1).
void blend_frames(const Motion& from, int a, int b, double t, Motion& to, int f_to) {
  const int J = from.num_joints();
  to.root_positions[f_to] = (1.0 - t) * from.root_positions[a] + t * from.root_positions[b];
  for (int j = 0; j < J; ++j) to.rotation(f_to, j) = slerp(from.rotation(a, j), from.rotation(b, j), t);
}

// Frame f_to of `to` = sum_k w[k] * frame (a + first + k) of `from`, the
// indices clamped to the clip (the end frames repeated as missing neighbours):
// root positions per coordinate; rotations per quaternion component, all
// brought into the hemisphere of frame a's, then normalised.
template <int n>
void stencil_frame(const Motion& from, int a, int first, const double (&w)[n], Motion& to, int f_to) {
  const int last = from.num_frames() - 1;
  int idx[n];
  for (int k = 0; k < n; ++k) idx[k] = std::clamp(a + first + k, 0, last);
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (int k = 0; k < n; ++k) p += w[k] * from.root_positions[idx[k]];
  to.root_positions[f_to] = p;
  for (int j = 0; j < from.num_joints(); ++j) {
    const Eigen::Vector4d ref = from.rotation(a, j).coeffs();
    Eigen::Vector4d q = Eigen::Vector4d::Zero();
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector4d c = from.rotation(idx[k], j).coeffs();
      q += w[k] * (c.dot(ref) < 0 ? -c : c);
    }
    Eigen::Quaterniond r;
    r.coeffs() = q.norm() > 1e-12 ? Eigen::Vector4d(q.normalized()) : ref;
    to.rotation(f_to, j) = r;
  }
}

// Uniform Catmull-Rom spline through frames a - 1 .. a + 2 at t in (0, 1).
void cubic_frame(const Motion& from, int a, double t, Motion& to, int f_to) {
  const double t2 = t * t, t3 = t2 * t;
  const double w[4] = {0.5 * (-t3 + 2 * t2 - t), 0.5 * (3 * t3 - 5 * t2 + 2), 0.5 * (-3 * t3 + 4 * t2 + t),
                       0.5 * (t3 - t2)};
  stencil_frame(from, a, -1, w, to, f_to);
}

// The Lagrange polynomial of degree 5 through frames a - 2 .. a + 3 at t in (0, 1).
void quintic_frame(const Motion& from, int a, double t, Motion& to, int f_to) {
  double w[6];
  for (int k = 0; k < 6; ++k) {
    w[k] = 1.0;
    for (int m = 0; m < 6; ++m) {
      if (m != k) w[k] *= (t + 2 - m) / static_cast<double>(k - m);
    }
  }
  stencil_frame(from, a, -2, w, to, f_to);
}

// Input frame position (in input frames, possibly fractional) of output
// frame i, snapped (snap_frame_position) and held at the last frame.
double source_position(int i, double fps_in, double fps_out, int frames_in) {
  double s = snap_frame_position(static_cast<double>(i) * fps_in / fps_out);
  if (s > frames_in - 1) s = frames_in - 1;
  return s;
}

}  // namespace

bool same_frame_rate(double a, double b) { return std::abs(a - b) <= 1e-5 * b; }

double snap_frame_position(double s) {
  const double r = std::round(s);
  return std::abs(s - r) <= 1e-5 * std::max(1.0, std::abs(r)) ? r : s;
}

Motion interpolate_motion(const Motion& input, const std::vector<int>& known) {
  check_shape(input);
  const int N = input.num_frames();
  check_known(known, N);
  Motion out = Motion::identity(input.skeleton, N, input.fps);
  size_t k = 0;  // known[k] is the first known frame >= f
  for (int f = 0; f < N; ++f) {
    while (k < known.size() && known[k] < f) ++k;
    if (k < known.size() && known[k] == f) {
      copy_frame(input, f, out, f);
    } else if (k == 0) {
      copy_frame(input, known.front(), out, f);
    } else if (k == known.size()) {
      copy_frame(input, known.back(), out, f);
    } else {
      const int a = known[k - 1], b = known[k];
      blend_frames(input, a, b, static_cast<double>(f - a) / (b - a), out, f);
    }
  }
  return out;
}

Motion zero_velocity_motion(const Motion& input, const std::vector<int>& known) {
  check_shape(input);
  const int N = input.num_frames();
  check_known(known, N);
  Motion out = Motion::identity(input.skeleton, N, input.fps);
  size_t k = 0;  // known[k] is the last known frame <= f, once one exists
  for (int f = 0; f < N; ++f) {
    while (k + 1 < known.size() && known[k + 1] <= f) ++k;
    copy_frame(input, known[k], out, f);
  }
  return out;
}

namespace {

// Resampling at continuous times (resample_interpolate()'s frame times and
// snapping): output frames on an input frame copy it, the others are
// `between(a, t, out, i)` at t in (0, 1) past input frame a.
template <class Between>
Motion resample_at_times(const Motion& input, double new_fps, int frames, Between between) {
  check_resample(input, new_fps, frames);
  const int N = input.num_frames();
  Motion out = Motion::identity(input.skeleton, frames, new_fps);
  for (int i = 0; i < frames; ++i) {
    const double s = source_position(i, input.fps, new_fps, N);
    const int a = static_cast<int>(std::floor(s));
    const double t = s - a;
    if (t == 0.0) {
      copy_frame(input, a, out, i);
    } else {
      between(a, t, out, i);
    }
  }
  return out;
}

}  // namespace

Motion resample_interpolate(const Motion& input, double new_fps, int frames) {
  return resample_at_times(input, new_fps, frames,
                           [&](int a, double t, Motion& out, int i) { blend_frames(input, a, a + 1, t, out, i); });
}

Motion resample_cubic(const Motion& input, double new_fps, int frames) {
  return resample_at_times(input, new_fps, frames,
                           [&](int a, double t, Motion& out, int i) { cubic_frame(input, a, t, out, i); });
}

Motion resample_quintic(const Motion& input, double new_fps, int frames) {
  return resample_at_times(input, new_fps, frames,
                           [&](int a, double t, Motion& out, int i) { quintic_frame(input, a, t, out, i); });
}

Motion resample_zero_velocity(const Motion& input, double new_fps, int frames) {
  check_resample(input, new_fps, frames);
  const int N = input.num_frames();
  Motion out = Motion::identity(input.skeleton, frames, new_fps);
  for (int i = 0; i < frames; ++i) {
    copy_frame(input, static_cast<int>(std::floor(source_position(i, input.fps, new_fps, N))), out, i);
  }
  return out;
}

Motion played_at_speed(const Motion& motion, double speed) {
  if (!(std::isfinite(speed) && speed > 0)) throw InputError("a playback speed must be finite and positive");
  Motion faster = motion;
  faster.fps = motion.fps * speed;  // resampled back to the motion's rate: frame i lands at position i * speed
  const int frames = static_cast<int>(std::floor((motion.num_frames() - 1) / speed + 1e-9)) + 1;
  return resample_cubic(faster, motion.fps, frames);
}

}  // namespace mf
