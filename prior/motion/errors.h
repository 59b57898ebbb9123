// Error types shared by every layer of motionfield.
#pragma once

#include <stdexcept>
#include <string>

namespace mf {

/// Bad input from the caller (a malformed file, an out-of-range keyframe, a
/// skeleton that does not match). The CLI maps it to exit code 2 and the C API
/// to its invalid-argument status. The message is meant for the user as is.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

/// Bad input of one kind: the request needs a model that is not loaded (the
/// prior, a transformer in-betweener). The C API can map it to its model
/// status instead of the invalid-argument one.
class ModelMissingError : public InputError {
 public:
  explicit ModelMissingError(const std::string& message) : InputError(message) {}
};

}  // namespace mf
