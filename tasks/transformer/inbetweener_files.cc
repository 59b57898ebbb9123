#include "tasks/transformer/inbetweener_files.h"

#include <filesystem>

#include "prior/inbetween/inbetweener_kinds.h"
#include "prior/motion/errors.h"
#include "prior/runtime/inbetween_runtime.h"
#include "prior/runtime/nemf_runtime.h"
#include "prior/util/binary_io.h"

namespace mf {

std::string inbetweener_file_name(const std::string& kind) { return inbetweener_kind(kind).file_name; }

std::string inbetweener_title(const std::string& kind) {
  const InbetweenerKind* k = find_inbetweener_kind(kind);
  return k ? k->title : kind;
}

std::string inbetweener_path_next_to(const std::string& prior_path, const std::string& kind) {
  return (std::filesystem::path(prior_path).parent_path() / inbetweener_file_name(kind)).string();
}

std::shared_ptr<const runtime::InbetweenerRuntime> checked_inbetweener(
    std::unique_ptr<const runtime::InbetweenerRuntime> model, const std::string& source, const std::string& kind,
    const runtime::NemfRuntime* prior) {
  if (!kind.empty() && model->kind() != kind)
    throw InputError(source + " holds a '" + model->kind() + "' model, not the expected '" + kind + "'");
  if (prior && !model->rig().skeleton.same_as(prior->rig().skeleton))
    throw InputError(source + ": the " + inbetweener_title(model->kind()) + "'s skeleton (" +
                     std::to_string(model->rig().num_joints()) + " joints) is not the prior's (" +
                     std::to_string(prior->rig().num_joints()) + " joints): train it on the prior's data");
  return std::shared_ptr<const runtime::InbetweenerRuntime>(std::move(model));
}

std::shared_ptr<const runtime::InbetweenerRuntime> inbetweener_from_bytes(const uint8_t* data, size_t size,
                                                                          const std::string& source,
                                                                          const std::string& kind,
                                                                          const runtime::NemfRuntime* prior) {
  return checked_inbetweener(runtime::inbetweener_runtime_from_bytes(data, size, source), source, kind, prior);
}

std::shared_ptr<const runtime::InbetweenerRuntime> load_inbetweener_file(const std::string& path,
                                                                         const std::string& kind,
                                                                         const runtime::NemfRuntime* prior) {
  const FileBytes bytes = read_file_bytes(path);
  return inbetweener_from_bytes(bytes.data(), bytes.size(), path, kind, prior);
}

void load_inbetweeners(const std::string& prior_path, const std::map<std::string, std::string>& named, bool strict,
                       ModelSet* models, const InbetweenerLog& log) {
  for (const InbetweenerKind& kind : inbetweener_kinds()) {
    const auto given = named.find(kind.name);
    const bool is_named = given != named.end() && !given->second.empty();
    const std::string file = is_named ? given->second : inbetweener_path_next_to(prior_path, kind.name);
    std::error_code ec;
    if (!is_named && !std::filesystem::exists(file, ec)) continue;
    if (log) log(kind.title, file);
    try {
      models->add_inbetweener(load_inbetweener_file(file, kind.name, models->model.get()));
    } catch (const std::exception& e) {
      if (is_named || strict) throw;
      models->inbetweener_errors[kind.name] = e.what();
    }
  }
}

void load_inbetweeners_next_to(const std::string& prior_path, ModelSet* models) {
  load_inbetweeners(prior_path, {}, false, models);
}

std::string missing_inbetweener_message(const std::string& what, const std::string& kind) {
  const InbetweenerKind* k = find_inbetweener_kind(kind);
  const std::string file = k ? "models/" + k->file_name : "a '" + kind + "' in-betweener";
  return what + " needs " + file + " (the " + inbetweener_title(kind) +
         "), and it is not loaded: put it next to the prior's model file";
}

const runtime::InbetweenerRuntime& require_inbetweener(const ModelSet& models, const std::string& kind,
                                                      const std::string& what) {
  if (const runtime::InbetweenerRuntime* model = models.inbetweener(kind)) return *model;
  std::string message = missing_inbetweener_message(what, kind);
  auto why = models.inbetweener_errors.find(kind);
  if (why != models.inbetweener_errors.end())
    message += "; the file next to the prior did not load: " + why->second;
  throw ModelMissingError(message);
}

}  // namespace mf
