#include "capi/src/jobs/models.h"

#include <utility>


namespace motionfield::jobs {

Models::Models(std::string explicit_path, std::vector<std::string> transformers)
    : explicit_path_(std::move(explicit_path)), transformers_(std::move(transformers)) {}

void Models::load_explicit() {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (explicit_path_.empty() || model_) return;
  use(Model::load(explicit_path_), explicit_path_);
}

const Model& Models::for_method(const std::string& method) {
  if (!explicit_path_.empty()) {
    load_explicit();
    return model_;
  }
  const bool needs = !method.empty() && find_method(method).needs_model();
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!method.empty() && !needs) return model_;  // empty: no --model, and the default one is not loaded
  load_default();
  if (needs && !model_)
    throw InputError("method '" + method + "' needs the prior, and no model is loaded (name one with --model)");
  return model_;
}

std::string Models::path() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return path_;
}

// Remembers a failed load, so that every job of a batch reports it.
void Models::load_default() {
  if (tried_default_) {
    if (!default_error_.empty()) throw InputError(default_error_);
    return;
  }
  tried_default_ = true;
  const std::string path = default_model_path();
  if (path.empty()) return;
  Model model;
  try {
    model = Model::load(path);
  } catch (const Error& e) {
    default_error_ = std::string("cannot load the default model: ") + e.what();
    throw InputError(default_error_);
  }
  use(std::move(model), path);
}

std::string Models::load_warnings_of(const Model& model) { return model ? model.load_warnings() : ""; }

void Models::use(Model model, const std::string& path) {
  for (const std::string& file : transformers_) model = model.with_inbetweener(file);
  model_ = std::move(model);
  path_ = path;
}

}  // namespace motionfield::jobs
