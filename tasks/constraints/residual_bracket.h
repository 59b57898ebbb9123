// Where a frame takes the residual of known values from (tasks/constraints/residuals.h):
// the known frames around it and the ramp between them. Torch-free: the
// residual overwrite (residuals.h), the libtorch energy's on-output blending
// (tasks/latent/energies.cc) and the Eigen runtime's (tasks/latent/runtime_blend.h)
// share it.
#pragma once

#include <cstddef>
#include <vector>

namespace mf {

/// 3 t^2 - 2 t^3: from 0 at t = 0 to 1 at t = 1 with zero slope at both ends.
double smoothstep(double t);

/// How the residual ramps between two known frames a < b, over
/// u = (f - a) / (b - a): linearly (u) or with smoothstep(u) (no kink at the
/// known frames).
enum class ResidualRamp { Linear, Smoothstep };

/// Where frame `f` takes its residual from, among the sorted, unique known
/// `frames` (non-empty): indices a <= b into `frames` and the weight s of
/// b's residual (the residual is r[a] (1 - s) + r[b] s). Between two known
/// frames, the ramp of the position between them; at a known frame, before
/// the first and after the last: a = b (that frame, the first, the last) and
/// s = 0.
struct ResidualBracket {
  size_t a = 0, b = 0;
  double s = 0.0;
};
ResidualBracket residual_bracket(int f, const std::vector<int>& frames, ResidualRamp ramp);

/// A window frame's residual_bracket() (smoothstep) as key indices: keys a
/// and b, the weight s of b's residual (float, as the energies use it), and
/// whether any key constrains the series (else a = b = 0, s = 0).
struct KeyBracket {
  int a = 0, b = 0;
  float s = 0.0f;
  bool has = false;
};

/// The KeyBracket of every frame 0..length-1 of a window (`out` resized)
/// among the keys k with on[k] (key_frames[k] their window frames, unique).
void key_brackets(const std::vector<int>& key_frames, const std::vector<char>& on, int length,
                  std::vector<KeyBracket>* out);

}  // namespace mf
