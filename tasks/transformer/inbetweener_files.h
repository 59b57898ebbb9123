// The in-betweeners' model files (prior/inbetween/inbetweener_kinds.h): where
// each kind's file is looked for (next to the prior's model file), loading one
// on the Eigen runtime (prior/runtime/inbetween_runtime.h) ready to be shared
// between threads, and the error of a method whose in-betweener is not loaded.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>

#include "tasks/context/task_context.h"

namespace mf {

namespace runtime {
class InbetweenerRuntime;
class NemfRuntime;
}

/// The file name of the product kind `kind` (InbetweenerKind::file_name);
/// InputError listing the kinds otherwise.
std::string inbetweener_file_name(const std::string& kind);

/// What an in-betweener of `kind` is called in messages (InbetweenerKind::title;
/// `kind` itself for a kind that is not the product's).
std::string inbetweener_title(const std::string& kind);

/// Where the in-betweener of `kind` is looked for next to the prior file
/// `prior_path`: the same directory, inbetweener_file_name(kind).
std::string inbetweener_path_next_to(const std::string& prior_path, const std::string& kind);

/// Checks a loaded in-betweener: of `kind` (unless empty) and on the skeleton
/// of `prior` (unless null). InputError naming `source` otherwise.
std::shared_ptr<const runtime::InbetweenerRuntime> checked_inbetweener(
    std::unique_ptr<const runtime::InbetweenerRuntime> model, const std::string& source, const std::string& kind,
    const runtime::NemfRuntime* prior = nullptr);

/// The in-betweener of a model file's bytes (`source` names it in errors:
/// InputError as the runtime's loader's and checked_inbetweener()'s).
std::shared_ptr<const runtime::InbetweenerRuntime> inbetweener_from_bytes(const uint8_t* data, size_t size,
                                                                          const std::string& source,
                                                                          const std::string& kind,
                                                                          const runtime::NemfRuntime* prior = nullptr);
/// The same from the file at `path` (FileError when it cannot be read).
std::shared_ptr<const runtime::InbetweenerRuntime> load_inbetweener_file(const std::string& path,
                                                                         const std::string& kind,
                                                                         const runtime::NemfRuntime* prior = nullptr);

/// Told the title and the path of each in-betweener file before it loads.
using InbetweenerLog = std::function<void(const std::string& title, const std::string& path)>;

/// Loads the in-betweener of every product kind into `models` (whose prior
/// must be set): the file `named` gives for the kind, else the one next to
/// `prior_path` when it exists. A named file that does not load throws; one
/// next to the prior is recorded in models->inbetweener_errors (the prior
/// alone stays usable), or thrown when `strict`. The one loader of the
/// in-betweeners of a model set: the C API's model loading and the
/// benchmark programs use it.
void load_inbetweeners(const std::string& prior_path, const std::map<std::string, std::string>& named, bool strict,
                       ModelSet* models, const InbetweenerLog& log = {});

/// load_inbetweeners with no named file, not strict: every file that exists
/// next to `prior_path`.
void load_inbetweeners_next_to(const std::string& prior_path, ModelSet* models);

/// The error of a method or initialiser (`what`, e.g. "method 'citl'") whose
/// in-betweener of `kind` is not loaded: names the file it needs.
std::string missing_inbetweener_message(const std::string& what, const std::string& kind);

/// The in-betweener of `kind` in `models`; throws mf::ModelMissingError with
/// missing_inbetweener_message(what, kind), and why its file did not load
/// when it did not, when it is not loaded.
const runtime::InbetweenerRuntime& require_inbetweener(const ModelSet& models, const std::string& kind,
                                                      const std::string& what);

}  // namespace mf
