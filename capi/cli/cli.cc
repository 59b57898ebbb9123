#include "cli.h"

#include <sys/stat.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
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

std::string printable(const std::string& text) {
  try {
    return printable_text(text);
  } catch (...) {  // out of memory: say so rather than print raw bytes
    return "(a message that could not be made printable)";
  }
}

void print_failure(const Failure& failure, const std::string& prefix) {
  const std::string line =
      prefix + (failure.exit_code == kExitBadInput ? "error" : "internal error") + ": " + failure.message;
  std::fprintf(stderr, "motionfield: %s\n", printable(line).c_str());
}

void print_warnings(const std::string& warnings, const std::string& prefix) {
  std::istringstream lines(warnings);
  for (std::string line; std::getline(lines, line);)
    std::fprintf(stderr, "motionfield: %s\n", printable(prefix + "warning: " + line).c_str());
}

std::string read_text_file(const std::string& path, const std::string& what, size_t max_bytes) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0)
    throw InputError("cannot open the " + what + " " + path + ": " + std::strerror(errno));
  const std::string cannot = "cannot read the " + what + " " + path + ": ";
  if (S_ISDIR(st.st_mode)) throw InputError(cannot + "it is a directory");
  if (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode)) throw InputError(cannot + "it is a device, not a file");
  const std::string too_large = cannot + "larger than the limit of " + std::to_string(max_bytes >> 20) + " MiB";
  if (S_ISREG(st.st_mode) && static_cast<uint64_t>(st.st_size) > max_bytes) throw InputError(too_large);
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) throw InputError("cannot open the " + what + " " + path + ": " + std::strerror(errno));
  std::string text;
  char buffer[1 << 16];
  size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, file)) > 0) {
    if (text.size() + n > max_bytes) {
      std::fclose(file);
      throw InputError(too_large);
    }
    text.append(buffer, n);
  }
  const int error = std::ferror(file) ? errno : 0;
  std::fclose(file);
  if (error != 0) throw InputError(cannot + std::strerror(error));
  return text;
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
