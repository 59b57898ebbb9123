// The context every task method runs in: the models it may use (the prior,
// the in-betweeners by kind, the prior rig's anatomy), the seed, and the
// progress callback and cancel flag of long-running methods; and the checks
// that a request fits it (the prior is loaded, a motion is on its skeleton).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "prior/model/rig_info.h"

namespace mf {
namespace runtime {
class NemfRuntime;
class InbetweenerRuntime;
}  // namespace runtime
class ReferenceEnergies;
struct RigAnatomy;

/// Progress of a long-running method (a solver's iterations).
struct TaskProgress {
  int iteration = 0;
  int max_iterations = 0;
  double energy = 0.0;
  /// The window being solved (0-based) and the window count; 0 and 0 when
  /// the method does not work window by window. TaskContext::report fills
  /// them from the context.
  int window = 0;
  int window_count = 0;
};

/// Thrown when a progress callback or the cancel flag stops a method.
class CancelledError : public std::runtime_error {
 public:
  CancelledError() : std::runtime_error("cancelled") {}
};

/// The models a request may use, loaded together (the C API's mf_model holds
/// one): the networks on the Eigen runtime (prior/runtime/), without libtorch.
/// Immutable once loaded, shared between threads; cheap to copy.
struct ModelSet {
  /// The prior (prior/runtime/nemf_runtime.h); required by methods with
  /// needs_model, unused by the baselines.
  std::shared_ptr<const runtime::NemfRuntime> model;
  /// The in-betweeners by kind (prior/runtime/inbetween_runtime.h: the
  /// product's kinds are inbetweener_kinds() of
  /// prior/inbetween/inbetweener_kinds.h), on the prior's skeleton. The C API
  /// loads each kind's file_name next to the prior's file
  /// (tasks/transformer/inbetweener_files.h).
  std::map<std::string, std::shared_ptr<const runtime::InbetweenerRuntime>> inbetweeners;
  /// Why a kind's file next to the prior did not load (absent kinds have no
  /// entry): the missing-model error of a method that needs it quotes it.
  std::map<std::string, std::string> inbetweener_errors;
  /// The anatomy of the prior's rig (prior/rig/retarget.h), needed to serve
  /// motions on other rigs; the C API loads motionfield-rig.json next to the
  /// prior's file. Null: only the model's own rig is served.
  std::shared_ptr<const RigAnatomy> model_anatomy;
  /// Why that file did not load ("" when it did or is absent).
  std::string model_anatomy_error;

  /// The in-betweener of `kind`; null when not loaded.
  const runtime::InbetweenerRuntime* inbetweener(const std::string& kind) const {
    auto it = inbetweeners.find(kind);
    return it == inbetweeners.end() ? nullptr : it->second.get();
  }
  /// Adds (or replaces) the in-betweener of `model`'s kind and forgets that
  /// kind's load error.
  void add_inbetweener(std::shared_ptr<const runtime::InbetweenerRuntime> model);
};

/// What a method may use besides its input: the models, the caller's rig map,
/// the seed, progress and cancel. Cheap to copy.
struct TaskContext : ModelSet {
  /// A rig map's JSON text ({"user joint": "model joint" or null}) that
  /// overrides the automatic map of another rig onto the model's; empty: automatic.
  std::string rig_map;
  /// Where `rig_map` came from (a file name) for its error messages; may be empty.
  std::string rig_map_source;
  uint64_t seed = 0;
  /// Iteration budget of iterative methods (the latent solvers, prior
  /// resampling, re-navigation): the most iterations of the full solve per
  /// window; 0 = each method's default.
  int max_iterations = 0;
  /// Called now and then by long methods; returning false cancels.
  std::function<bool(const TaskProgress&)> progress;
  /// Non-zero cancels (thread-safe; set from any thread).
  const std::atomic<int>* cancel = nullptr;
  /// The window a windowed solver is on, and how many it has (0: not
  /// windowed): set on a copy of the context per window, passed on in reports.
  int window = 0;
  int window_count = 0;
  /// Where methods append named numbers about their solve, for benchmarks
  /// and diagnostics (the latent solvers: each window's energy terms before
  /// and after the minimisation, complete_motion() in
  /// tasks/latent/latent_solver.h). Null: none are kept. Not thread-safe: one
  /// sink per concurrent call.
  std::vector<std::pair<std::string, double>>* diagnostics = nullptr;
  /// The latent solvers' in-betweening and gap filling return interpolation
  /// where the prior cannot reach the keys (tasks/latent/fallback.h); false
  /// keeps their own result everywhere.
  bool interpolation_fallback = true;
  /// Energies other than the runtime's for the latent solvers to minimise
  /// (tasks/latent/window_energies.h): the libtorch reference of
  /// tasks/reference/, for equivalence tests and benchmarks. Null in the
  /// product: the runtime's.
  std::shared_ptr<const ReferenceEnergies> reference;

  /// Calls `progress` (with this context's window) and checks `cancel`;
  /// throws CancelledError when asked to stop.
  void report(TaskProgress p) const {
    p.window = window;
    p.window_count = window_count;
    if ((cancel && cancel->load() != 0) || (progress && !progress(p))) throw CancelledError();
  }
};

/// The prior of `ctx`; throws mf::ModelMissingError "<what> needs a model
/// (the prior), and none is loaded" when there is none.
const runtime::NemfRuntime& require_prior(const TaskContext& ctx, const std::string& what);

}  // namespace mf
