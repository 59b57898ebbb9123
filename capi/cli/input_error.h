// The CLI's own "bad input" (exit code 2): what it checks itself, before or
// around the C API (whose failures arrive as motionfield::Error).
#pragma once

#include <stdexcept>
#include <string>

namespace motionfield::cli {

/// Bad input from the user of the CLI; the message is meant for them as is.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace motionfield::cli
