// The penalties of the Eigen runtime's energy terms (tasks/latent/runtime_energy.h)
// with their derivatives: penalty_of_angle and penalty_of_squared of
// tasks/latent/energies.cc. Internal to runtime_energy*.cc.
#pragma once

#include <cmath>

#include "tasks/latent/energy_weights.h"

namespace mf::runtime_penalties {

/// A penalised residual and its derivative with respect to the residual.
struct Penalised {
  float value, slope;
};

/// The penalty of an angle (rad).
inline Penalised angle_penalty(float angle, Penalty p) {
  return p == Penalty::Squared ? Penalised{angle * angle, 2 * angle} : Penalised{angle, 1.0f};
}

/// The penalty of a distance given as its square d2, and its derivative with
/// respect to d2 (the 1e-12 of energies.cc smooths the absolute penalty at 0).
inline Penalised squared_penalty(float d2, Penalty p) {
  if (p == Penalty::Squared) return {d2, 1.0f};
  const float s = std::sqrt(d2 + 1e-12f);
  return {s, 0.5f / s};
}

}  // namespace mf::runtime_penalties
