// The product's kinds of transformer in-betweener (prior/inbetween/inbetweener.h
// has their libtorch networks, prior/runtime/inbetween_runtime.h their Eigen
// forward passes): what the rest of the product derives from a kind (its
// methods, initialisers, model file next to the prior, trainer subcommand and
// benchmark flags). Without libtorch.
#pragma once

#include <string>
#include <vector>

namespace mf {

/// One output stage of a kind, as the product offers it: the stage alone is
/// the method `name` (one pass), its output encoded by the prior is the
/// initialiser "<name>-encoder", and the latent solver started there is the
/// method "nemf-<name>".
struct InbetweenerStage {
  std::string name;         ///< "context"; also the model's stage_names() entry
  std::string description;  ///< "Context Transformer only", in method lists
};

/// A kind of in-betweener.
struct InbetweenerKind {
  std::string name;                      ///< "twostage": the model file's kind
  std::string title;                     ///< "two-stage transformer", in messages
  std::string file_name;                 ///< "motionfield-twostage.mfm", next to the prior's file
  std::vector<InbetweenerStage> stages;  ///< in the model's stage_names() order
  /// The network is conditioned on a ground trajectory, so its methods follow
  /// a trajectory the caller gives.
  bool reads_trajectory = false;
  /// Its methods hold planted feet with the model's contact head (foot
  /// locking in inbetweener_fill() of tasks/transformer/inbetweener_fill.h): set where it
  /// measured better (docs/BENCHMARKS.md, "Long transitions").
  bool locks_feet = false;
};

/// The product's kinds, in a fixed order (two-stage, CITL, keyframe). Adding a
/// kind is its entry here, its libtorch network (inbetween_network() of
/// inbetweener.h) and its runtime (inbetween_runtime.cc).
const std::vector<InbetweenerKind>& inbetweener_kinds();
/// The product's kind called `name`, or null.
const InbetweenerKind* find_inbetweener_kind(const std::string& name);
/// The same; mf::InputError listing the product's kinds when there is none.
const InbetweenerKind& inbetweener_kind(const std::string& name);
/// The product kind that has a stage called `stage`, or null; *index (if
/// non-null) receives the stage's index.
const InbetweenerKind* find_inbetweener_stage(const std::string& stage, int* index = nullptr);

}  // namespace mf
