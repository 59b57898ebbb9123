// Interpolation and resampling of motions: interpolation between known
// frames, zero velocity, and resampling at continuous times (linear, spline,
// hold). They read only the known frames of their input; unknown frames may
// hold anything (even NaN) and are never read. Known frames are copied bit for
// bit into the output (no round trip through SLERP), so they match the input
// exactly.
//
// Every function returns a new motion on the input's skeleton. They throw
// mf::InputError on arguments that would make them read out of bounds (known
// frames empty, unsorted or out of range; a motion whose rotation count does not
// match its frames and joints; a non-positive fps or output frame count); the
// user-facing validation with friendlier messages is in tasks/methods/jobs.h.
#pragma once

#include <vector>

#include "prior/motion/motion.h"

namespace mf {

/// Interpolation: root position LERP and local rotations SLERP (shortest path,
/// mf::slerp) between the surrounding known frames a < f < b at
/// t = (f - a) / (b - a). Frames before the first known frame copy it, frames
/// after the last copy the last. `known` must be sorted, unique, in range and
/// non-empty (checked by the caller, see tasks/methods/jobs.h). Output: the input's
/// length and fps.
Motion interpolate_motion(const Motion& input, const std::vector<int>& known);

/// Zero-velocity: every unknown frame repeats the last known frame before it
/// (or the first known frame when none precedes it). Output: the input's
/// length and fps.
Motion zero_velocity_motion(const Motion& input, const std::vector<int>& known);

/// True when frame rates `a` and `b` are the same within 1e-5 relative to
/// `b` (BVH frame times carry about six digits: 0.0333333 s is 30.00003 fps).
bool same_frame_rate(double a, double b);

/// A frame position (in frames, possibly fractional) snapped to the nearest
/// whole frame when within 1e-5 relative of it (at least 1e-5), so that
/// frames that coincide in time copy each other exactly despite six-digit
/// frame times.
double snap_frame_position(double s);

/// Resampling by interpolation at continuous times: output frame i sits at time
/// i / new_fps, i.e. at input frame position s = i * input.fps / new_fps; root
/// LERP and rotation SLERP between input frames floor(s) and floor(s) + 1.
/// Positions within 1e-5 relative of an integer copy that input frame exactly
/// (BVH frame times carry about six digits: 0.0333333 s must still mean 30 fps);
/// positions past the last input frame hold it. `frames` is the output frame
/// count (see resampled_frame_count() in tasks/methods/jobs.h); the output's fps is
/// `new_fps`.
Motion resample_interpolate(const Motion& input, double new_fps, int frames);

/// Resampling by a uniform Catmull-Rom spline through the input frames (C1;
/// the end frames repeated as the missing neighbours): the same frame times,
/// exact copies and held end as resample_interpolate(); root positions per
/// coordinate, rotations per quaternion component (the four neighbours brought
/// into one hemisphere, the result normalised).
Motion resample_cubic(const Motion& input, double new_fps, int frames);

/// Resampling by local quintic interpolation: between input frames a and a + 1
/// the Lagrange polynomial of degree 5 through frames a - 2 .. a + 3 (ends
/// repeated like resample_cubic()'s), per root coordinate and quaternion
/// component like resample_cubic(). C0 only, but its error on captured motion
/// sampled at 15 fps and below is 10-20 % under the spline's
/// (docs/BENCHMARKS.md, "Resampling").
Motion resample_quintic(const Motion& input, double new_fps, int frames);

/// `motion` played `speed` times as fast at its own frame rate (frame i of the
/// result is the motion at frame position i * speed; resample_cubic() between
/// frames); the result covers the whole motion. Throws InputError unless speed
/// is finite and positive.
Motion played_at_speed(const Motion& motion, double speed);

/// Resampling by holding the most recent input frame (zero velocity): output
/// frame i copies input frame floor(s), s as above.
Motion resample_zero_velocity(const Motion& input, double new_fps, int frames);

}  // namespace mf
