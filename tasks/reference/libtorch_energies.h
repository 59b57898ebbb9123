// The latent solver's window energies on libtorch (tasks/reference/energies.h,
// by autograd through FlatLatentEnergy) as TaskContext::reference: the
// solver's old path, for the tests that hold the Eigen runtime's solve to it
// and for the benchmarks that time it on the same windows
// (solver-bench --libtorch-energy).
#pragma once

#include <memory>

#include "tasks/latent/window_energies.h"

namespace mf {

class NemfModel;

/// The energies of `model` (the same prior as the context's runtime, loaded
/// with libtorch) for the latent solver.
std::shared_ptr<const ReferenceEnergies> libtorch_energies(std::shared_ptr<const NemfModel> model);

}  // namespace mf
