// What the latent solver minimises for one window: its full and keys-only
// energies and the decode of a solution. The product's are the Eigen
// runtime's (tasks/latent/runtime_energy.h, made by complete_motion());
// TaskContext::reference can put others in their place (ReferenceEnergies:
// tasks/reference/ implements it on libtorch, for equivalence tests and for
// benchmarks that time the old libtorch path on the same windows).
#pragma once

#include <Eigen/Core>
#include <memory>

#include "tasks/latent/energy_weights.h"
#include "tasks/latent/latent_optimizer.h"
#include "tasks/latent/window_problem.h"

namespace mf {

/// One window's energies. Not thread-safe: one per window being solved.
class WindowEnergies {
 public:
  virtual ~WindowEnergies() = default;
  /// Under the solve's weights.
  virtual DirectLatentEnergy& full() = 0;
  /// Under the keys-only weights of the first stage.
  virtual DirectLatentEnergy& keyed() = 0;
  /// The window decoded at codes z_l [zl], z_g [zg].
  virtual DecodedWindow decode(const Eigen::VectorXf& z_l, const Eigen::VectorXf& z_g) = 0;
  /// True for the Eigen runtime's energies (SolveSummary::runtime_energy).
  virtual bool on_runtime() const = 0;
};

/// Energies other than the runtime's (TaskContext::reference).
class ReferenceEnergies {
 public:
  virtual ~ReferenceEnergies() = default;
  /// The energies of `problem` under weights `full` and `keyed`; `problem`
  /// outlives the result.
  virtual std::unique_ptr<WindowEnergies> latent_window(const RuntimeWindowProblem& problem,
                                                        const EnergyWeights& full,
                                                        const EnergyWeights& keyed) const = 0;
};

}  // namespace mf
