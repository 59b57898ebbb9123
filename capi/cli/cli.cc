#include "cli.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <exception>
#include <sstream>

#include "input_error.h"
#include "motionfield.hpp"

namespace motionfield::cli {

std::vector<std::string> Settings::transformers() const {
  std::vector<std::string> all = twostage;
  all.insert(all.end(), citl.begin(), citl.end());
  return all;
}

Failure current_failure() {
  try {
    throw;
  } catch (const InputError& e) {
    return {kExitBadInput, e.what()};
  } catch (const Error& e) {
    switch (e.status()) {
      case MF_ERROR_INVALID_ARGUMENT:
      case MF_ERROR_IO:
      case MF_ERROR_MODEL:
      case MF_ERROR_UNSUPPORTED:
        return {kExitBadInput, e.what()};
      default:
        return {kExitInternal, std::string(e.status_name()) + ": " + e.what()};
    }
  } catch (const std::exception& e) {
    return {kExitInternal, e.what()};
  } catch (...) {
    return {kExitInternal, "unknown exception"};
  }
}

void print_failure(const Failure& failure, const std::string& prefix) {
  std::fprintf(stderr, "motionfield: %s%s: %s\n", prefix.c_str(),
               failure.exit_code == kExitBadInput ? "error" : "internal error", failure.message.c_str());
}

void print_warnings(const std::string& warnings, const std::string& prefix) {
  std::istringstream lines(warnings);
  for (std::string line; std::getline(lines, line);)
    std::fprintf(stderr, "motionfield: %swarning: %s\n", prefix.c_str(), line.c_str());
}

double units_scale(const std::string& units, const std::string& what) {
  if (units.empty() || units == "auto") return 0.0;
  double v = 0;
  const auto r = std::from_chars(units.data(), units.data() + units.size(), v);
  if (r.ec == std::errc() && r.ptr == units.data() + units.size()) {
    if (!(std::isfinite(v) && v > 0)) throw InputError(what + " must be positive, not " + units);
    return v;
  }
  try {
    return length_unit_scale(units);
  } catch (const Error& e) {
    throw InputError(what + ": " + e.what() + "; auto (the default) detects it");
  }
}

}  // namespace motionfield::cli
