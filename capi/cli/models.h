// Which model the CLI's jobs run with.
#pragma once

#include <atomic>
#include <string>
#include <vector>

#include "motionfield.hpp"

namespace motionfield::cli {

/// The model of the jobs: --model PATH (loaded once, up front, by
/// load_explicit), else the default model, loaded on first need: when a job
/// names no method (the default method depends on the model) or one that needs
/// the model. The C API loads the transformer files next to the model;
/// `transformers` (--twostage, --citl) add or replace them.
class Models {
 public:
  Models(std::string explicit_path, std::vector<std::string> transformers);

  /// Loads --model, if given (bad input if it does not load).
  void load_explicit();

  /// The model for a job with `method` ("" = the default method): an empty
  /// Model when the method needs none and no --model was given.
  const Model& for_method(const std::string& method);

  /// The model for `what` (a command), which always needs one.
  const Model& required(const std::string& what);

  /// The loaded model's path ("" before one is loaded).
  const std::string& path() const { return path_; }

  /// The transformer files next to the model that were there but did not
  /// load (a truncated file: the default method then quietly runs without
  /// it), one warning per line naming the file and the reason; given once
  /// per process ("" afterwards, and when everything loaded). Thread-safe once
  /// the model is loaded (batch --jobs loads it before the workers start).
  std::string load_warnings();

  /// Those warnings of `model` (mf_model_describe), every time.
  static std::string load_warnings_of(const Model& model);

 private:
  void load_default();
  void use(Model model, const std::string& path);

  std::string explicit_path_, path_, default_error_;
  std::vector<std::string> transformers_;
  bool tried_default_ = false;
  std::atomic<bool> warned_{false};  // batch workers ask concurrently
  Model model_;
};

}  // namespace motionfield::cli
