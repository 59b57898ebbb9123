#include "cli.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "motionfield.hpp"

namespace motionfield::cli {

std::vector<std::string> Settings::transformers() const {
  std::vector<std::string> all = twostage;
  all.insert(all.end(), citl.begin(), citl.end());
  return all;
}

void print_failure(const Failure& failure, const std::string& prefix) {
  std::fputs(failure_line(failure, prefix).c_str(), stderr);
}

void print_warnings(const std::string& warnings, const std::string& prefix) {
  std::fputs(warning_lines(warnings, prefix).c_str(), stderr);
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

}  // namespace motionfield::cli
