// The one conversion from the tensor WindowProblem (tasks/latent/energies.h)
// to the Eigen runtime's RuntimeWindowProblem (tasks/latent/runtime_energy.h),
// so that a solver can evaluate the same window either way.
#pragma once

#include "tasks/latent/energies.h"
#include "tasks/latent/runtime_energy.h"

namespace mf {

/// The keys' targets copied to float matrices (one row per key) for a rig of
/// `joints` joints; the constraints of terms the runtime energy does not port
/// (effectors, contact pins, trajectory rows) are only counted.
RuntimeWindowProblem to_runtime_problem(const WindowProblem& problem, int joints);

}  // namespace mf
