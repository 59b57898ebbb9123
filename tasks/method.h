// Methods: the named algorithms behind every task ("interp", "zerovel", the
// prior's methods, the solvers, the transformers), and the context they run in.
// tasks/jobs.h validates input and dispatches to them by name.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "prior/motion/motion.h"

namespace mf {

class NemfModel;
class InbetweenModel;
struct RigAnatomy;

/// Progress of a long-running method (a solver's iterations).
struct TaskProgress {
  int iteration = 0;
  int max_iterations = 0;
  double energy = 0.0;
};

/// Thrown when a progress callback or the cancel flag stops a method.
class CancelledError : public std::runtime_error {
 public:
  CancelledError() : std::runtime_error("cancelled") {}
};

/// What a method may use besides its input. Cheap to copy.
struct TaskContext {
  /// The prior; required by methods with needs_model, unused by the baselines.
  /// Immutable and shared between threads.
  std::shared_ptr<const NemfModel> model;
  /// The transformer in-betweeners (prior/inbetween/inbetweener.h), each null
  /// when not loaded: `twostage` (kind "twostage": methods "context", "detail",
  /// the initialisers "context-encoder", "detail-encoder") and `citl` (kind
  /// "citl": method "citl", initialiser "citl-encoder"). On the prior's
  /// skeleton; frozen (set_requires_grad(false)), immutable and shared between
  /// threads like the prior. The C API loads them from
  /// motionfield-twostage.mfm and motionfield-citl.mfm next to the prior's file.
  std::shared_ptr<const InbetweenModel> twostage;
  std::shared_ptr<const InbetweenModel> citl;
  /// The anatomy of the prior's rig (prior/rig/retarget.h), needed to serve
  /// motions on other rigs; the C API loads motionfield-rig.json next to the
  /// prior's file. Null: only the model's own rig is served.
  std::shared_ptr<const RigAnatomy> model_anatomy;
  /// A rig map's JSON text ({"user joint": "model joint" or null}) that
  /// overrides the automatic map of another rig onto the model's; empty: automatic.
  std::string rig_map;
  uint64_t seed = 0;
  /// Called now and then by long methods; returning false cancels.
  std::function<bool(const TaskProgress&)> progress;
  /// Non-zero cancels (thread-safe; set from any thread).
  const std::atomic<int>* cancel = nullptr;

  /// The transformer of `kind` ("twostage" or "citl"); null when not loaded
  /// or for any other kind.
  const InbetweenModel* inbetweener(const std::string& kind) const {
    if (kind == "twostage") return twostage.get();
    if (kind == "citl") return citl.get();
    return nullptr;
  }

  /// Calls `progress` and checks `cancel`; throws CancelledError when asked to stop.
  void report(const TaskProgress& p) const {
    if ((cancel && cancel->load() != 0) || (progress && !progress(p))) throw CancelledError();
  }
};

struct Method {
  std::string name;
  std::string description;
  bool needs_model = false;
  /// Kind of transformer in-betweener the method needs besides the prior
  /// ("twostage" or "citl", see TaskContext); empty for none.
  std::string needs_inbetweener;
  /// Completes a motion from its known frames (sorted, unique, at least two,
  /// in range): every other frame is produced, known frames come out as given.
  /// Unknown input frames must never be read. Null when unsupported.
  std::function<Motion(const Motion& input, const std::vector<int>& known, const TaskContext& ctx)> complete;
  /// Resamples to `fps` with exactly `frames` output frames at times i / fps.
  /// Null when unsupported.
  std::function<Motion(const Motion& input, double fps, int frames, const TaskContext& ctx)> resample;
};

/// The method families, each defined beside its implementation.
std::vector<Method> baseline_methods();  // tasks/baselines.cc
std::vector<Method> prior_methods();     // tasks/prior_methods.cc
std::vector<Method> solver_methods();    // tasks/solver_methods.cc
std::vector<Method> transformer_methods();  // tasks/transformer_methods.cc

}  // namespace mf
