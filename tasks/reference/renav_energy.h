// Re-navigation's energy (tasks/renav/renav.h describes its terms) on
// libtorch, by autograd: the reference that tests/runtime_renav_equivalence_test.cc
// holds the runtime's energy (tasks/renav/renav_runtime_energy.h) to.
#pragma once

#include <ATen/core/Tensor.h>

#include "prior/model/rig_info.h"
#include "tasks/latent/window_problem.h"
#include "tasks/reference/latent_energy.h"
#include "tasks/renav/renav_window.h"

namespace mf {

class NemfModel;

/// The energy and its weighted terms (names "path", "joints", "heading",
/// "foot_skating", "continuity"; only the active ones, in that order).
using RenavEnergy = EnergyTerms;

/// The energy of a given canonical window motion: local rotations
/// [1, T, J, 3, 3] (root in the canonical frame), root positions [1, T, 3]
/// (canonical) and foot contact probabilities [1, T, F] (may be undefined when
/// foot_skating is 0). Differentiable in the rotations and positions.
RenavEnergy renav_motion_energy(const RigInfo& rig, double fps, const RenavWindow& window, const RenavWeights& weights,
                                const at::Tensor& local_rotations, const at::Tensor& root_positions,
                                const at::Tensor& contacts);

/// The energy of latent codes z_l [1, zl], z_g [1, zg]: the window decoded at
/// frames 0..T-1, root path from the GMP starting at the origin, then
/// renav_motion_energy(). Differentiable with respect to the codes (the
/// caller freezes the network).
RenavEnergy evaluate_renav_energy(const NemfModel& model, const RenavWindow& window, const RenavWeights& weights,
                                  const at::Tensor& z_l, const at::Tensor& z_g);

/// The decoded window (no grad): local rotations, root positions and contact
/// probabilities, canonical.
DecodedWindow decode_renav_window(const NemfModel& model, const RenavWindow& window, const at::Tensor& z_l,
                                  const at::Tensor& z_g);

}  // namespace mf
