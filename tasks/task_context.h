// The context every task method runs in: the models it may use (the prior,
// the transformer in-betweeners, the prior rig's anatomy), the seed, and the
// progress callback and cancel flag of long-running methods; and the checks
// that a request fits it (the prior is loaded, a motion is on its skeleton).
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

namespace mf {

class NemfModel;
class InbetweenModel;
struct RigAnatomy;
struct RigInfo;
struct Skeleton;

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

/// The prior of `ctx`; throws mf::ModelMissingError "<what> needs the prior,
/// and no model is loaded" when there is none.
const NemfModel& require_prior(const TaskContext& ctx, const std::string& what);

/// Throws mf::InputError "the <whose>'s skeleton does not match the model's:
/// ..." unless `skeleton` has the joints (names) and parents of `rig`'s.
void check_model_skeleton(const RigInfo& rig, const Skeleton& skeleton, const std::string& whose);

}  // namespace mf
