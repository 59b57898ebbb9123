// Which model the jobs of a run use.
#pragma once

#include <mutex>
#include <string>
#include <vector>

#include "motionfield.hpp"

namespace motionfield::jobs {

/// The model of the jobs: an explicit path (--model PATH, loaded once, up
/// front, by load_explicit), else the default model, loaded on first need:
/// when a job names no method (the default method depends on the model) or
/// one that needs the model. The C API loads the transformer files next to
/// the model; `transformers` (--twostage, --citl) add or replace them.
/// Thread-safe.
class Models {
 public:
  Models(std::string explicit_path, std::vector<std::string> transformers);

  /// Loads the explicit model, if given (bad input if it does not load).
  void load_explicit();

  /// The model for a job with `method` ("" = the default method): an empty
  /// Model when the method needs none and no explicit model was given.
  const Model& for_method(const std::string& method);

  /// The loaded model's path ("" before one is loaded).
  std::string path() const;

  /// The transformer files next to `model` that were there but did not load
  /// (mf_model_get_load_warnings), one warning per line; "" for no model.
  static std::string load_warnings_of(const Model& model);

 private:
  void load_default();
  void use(Model model, const std::string& path);

  std::string explicit_path_, path_, default_error_;
  std::vector<std::string> transformers_;
  bool tried_default_ = false;
  Model model_;
  mutable std::mutex mutex_;  // jobs run side by side ask for the model
};

}  // namespace motionfield::jobs
