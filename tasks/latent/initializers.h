// Initialisers of the latent solvers: where the optimisation of (z_l, z_g)
// starts. The solver asks an initialiser for the codes of one window, given the
// window's constraints; the default is NeMF's (fill the unknown frames by
// interpolation, encode the filled window, take the posterior means). Other
// initialisers implement the same interface and are passed to the solver
// through LatentSolverOptions::initializer, or made by name with
// make_initializer(): the transformer initialisers fill the window with a
// transformer in-betweener instead of interpolation (TransformerEncoderInitializer).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "prior/motion/motion.h"
#include "tasks/constraints/motion_constraints.h"
#include "tasks/context/task_context.h"

namespace mf {


/// Starting codes of one window.
struct InitialGuess {
  Eigen::VectorXf z_l;  ///< [zl]
  Eigen::VectorXf z_g;  ///< [zg]
};

/// What an initialiser knows about a window. `window` holds the window's frames
/// (world coordinates, the input's skeleton); only what `constraints` names is
/// meaningful, everything else must not be read. `constraints` are
/// window-relative and `anchor` is the window frame the solver canonicalises at
/// (a key that fixes the root).
struct InitRequest {
  const runtime::NemfRuntime* model = nullptr;  ///< the prior
  const Motion* window = nullptr;
  const MotionConstraints* constraints = nullptr;
  int anchor = 0;
  const TaskContext* context = nullptr;  ///< seed for initialisers that sample
};

/// The interface. Implementations must be deterministic for a given request
/// and seed, thread-safe (const), and must not keep references to the request.
class LatentInitializer {
 public:
  virtual ~LatentInitializer() = default;
  virtual std::string name() const = 0;
  virtual InitialGuess initialize(const InitRequest& request) const = 0;
  /// For inputs longer than the prior's window: the whole input (world
  /// coordinates) filled under the whole input's `constraints` the way this
  /// initialiser fills one window, or nullopt when it has no such fill (then
  /// every window is initialised by initialize()). complete_motion() encodes
  /// each window's slice of it instead, so that a window holding no key on its
  /// far side (the first window of a long gap) still starts from a motion
  /// that heads for the next key rather than one that holds the last.
  virtual std::optional<Motion> fill_input(const Motion& input, const MotionConstraints& constraints,
                                           const TaskContext& context) const;
};

/// NeMF's initialiser ("interp-encoder"): unknown frames filled by interpolation
/// (fill_by_interpolation() of tasks/constraints/interpolation_fill.h: interpolate_motion when every
/// key is a full pose; with partial keys each joint is interpolated over the
/// keys that constrain it, the root position over the keys that give it, and
/// a joint no key constrains keeps the identity), the filled window
/// canonicalised at the anchor and encoded; the codes are the posterior means.
class InterpolationEncoderInitializer : public LatentInitializer {
 public:
  std::string name() const override { return "interp-encoder"; }
  InitialGuess initialize(const InitRequest& request) const override;
  std::optional<Motion> fill_input(const Motion& input, const MotionConstraints& constraints,
                                   const TaskContext& context) const override;
};

/// The prior's mean codes (zeros), for comparison.
class ZeroInitializer : public LatentInitializer {
 public:
  std::string name() const override { return "zero"; }
  InitialGuess initialize(const InitRequest& request) const override;
};

/// The transformer initialisers: the window's constraints (full and partial
/// keys, each joint's rotation and the root position known where a key gives
/// them) -> one pass of a transformer in-betweener (inbetweener_fill() of
/// tasks/transformer/inbetweener_fill.h: gaps longer than the transformer's window stay
/// interpolated, frames before the first and after the last key that fixes
/// the root are held) -> the filled window canonicalised at the anchor and
/// encoded (encode_window); the codes are the posterior means.
/// One per stage of every in-betweener kind, "<stage>-encoder"
/// (prior/inbetween/inbetweener_kinds.h InbetweenerKind::stages):
///   "context-encoder"  stage 0 of the two-stage model
///   "detail-encoder"   stage 1 of the two-stage model
///   "citl-encoder"     the CITL model
/// The transformer is the one bound at construction, else the request
/// context's; initialize() throws mf::ModelMissingError when there is none.
class TransformerEncoderInitializer : public LatentInitializer {
 public:
  /// `kind` an in-betweener kind; `stage` 0-based, -1 = the last.
  TransformerEncoderInitializer(std::string name, std::string kind, int stage,
                                std::shared_ptr<const runtime::InbetweenerRuntime> bound = nullptr);
  std::string name() const override { return name_; }
  InitialGuess initialize(const InitRequest& request) const override;
  /// One pass of the transformer over the whole input (its own windows,
  /// inbetweener_fill()).
  std::optional<Motion> fill_input(const Motion& input, const MotionConstraints& constraints,
                                   const TaskContext& context) const override;
  const std::string& kind() const { return kind_; }

 private:
  const runtime::InbetweenerRuntime& transformer(const TaskContext* context) const;
  std::string name_, kind_;
  int stage_;
  std::shared_ptr<const runtime::InbetweenerRuntime> bound_;
};

/// Names accepted by make_initializer(), the default first: "interp-encoder",
/// "zero", "context-encoder", "detail-encoder", "citl-encoder".
std::vector<std::string> initializer_names();
/// The initialiser called `name`; throws mf::InputError listing the names
/// otherwise. Transformer initialisers made this way take their model from
/// the request's context at each call.
std::shared_ptr<const LatentInitializer> make_initializer(const std::string& name);
/// The same, with a transformer initialiser bound to the transformer of
/// `context` (InputError naming the missing file when it has none), so that
/// it needs no context at solve time.
std::shared_ptr<const LatentInitializer> make_initializer(const std::string& name, const TaskContext& context);

/// The window `window` (all frames meaningful) canonicalised at `anchor` and
/// encoded: the posterior means. For initialisers that produce a full motion.
InitialGuess encode_window(const runtime::NemfRuntime& model, const Motion& window, int anchor);
/// encode_window() with the request's prior and anchor.
InitialGuess encode_window(const InitRequest& request, const Motion& window);

}  // namespace mf
