// The transformer in-betweeners' model files (prior/inbetween/inbetweener.h):
// their names, where they are looked for (next to the prior's model file),
// loading one ready to be shared between threads, and the error of a method
// whose transformer is not loaded.
#pragma once

#include <memory>
#include <string>

#include "tasks/task_context.h"

namespace mf {

class InbetweenModel;

/// Model file names of the transformers, looked for in the directory of the
/// prior's model file.
constexpr char kTwoStageFileName[] = "motionfield-twostage.mfm";
constexpr char kCitlFileName[] = "motionfield-citl.mfm";

/// kTwoStageFileName for "twostage", kCitlFileName for "citl"; InputError otherwise.
std::string inbetweener_file_name(const std::string& kind);

/// What a transformer of `kind` is called in messages ("two-stage
/// transformer", "CITL transformer"; `kind` itself for another kind).
std::string inbetweener_title(const std::string& kind);

/// Where the transformer of `kind` is looked for next to the prior file
/// `prior_path`: the same directory, inbetweener_file_name(kind).
std::string inbetweener_path_next_to(const std::string& prior_path, const std::string& kind);

/// Loads a transformer file (load_inbetweener), checks that it is of `kind`
/// (InputError naming the file otherwise) and freezes it (no gradients for
/// its parameters), ready to be shared between threads.
std::shared_ptr<const InbetweenModel> load_frozen_inbetweener(const std::string& path, const std::string& kind);

/// The error of a method or initialiser (`what`, e.g. "method 'citl'") whose
/// transformer of `kind` is not loaded: names the file it needs.
std::string missing_inbetweener_message(const std::string& what, const std::string& kind);

/// The transformer of `kind` in `ctx`; throws mf::ModelMissingError with
/// missing_inbetweener_message(what, kind) when it is not loaded.
const InbetweenModel& require_inbetweener(const TaskContext& ctx, const std::string& kind, const std::string& what);

}  // namespace mf
