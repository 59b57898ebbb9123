#include "prior/util/blas.h"

#include <dlfcn.h>

#include <algorithm>
#include <filesystem>
#include <system_error>

namespace mf {

namespace {

// A symbol of the process: first the global scope, then libopenblas.so.0 if it
// is loaded but not global (a library opened with RTLD_LOCAL, as ctypes does).
void* find_symbol(const char* name, const char* library) {
  if (void* s = dlsym(RTLD_DEFAULT, name)) return s;
  void* handle = dlopen(library, RTLD_LAZY | RTLD_NOLOAD);
  if (!handle) return nullptr;
  void* s = dlsym(handle, name);
  dlclose(handle);
  return s;
}

}  // namespace

void set_blas_threads(int n) {
  using SetThreads = void (*)(int);
  if (auto set = reinterpret_cast<SetThreads>(find_symbol("openblas_set_num_threads", "libopenblas.so.0")))
    set(std::max(1, n));
}

void keep_blas_single_threaded() { set_blas_threads(1); }

std::string blas_library() {
  void* sgemm = find_symbol("sgemm_", "libblas.so.3");
  Dl_info info;
  if (!sgemm || !dladdr(sgemm, &info) || !info.dli_fname) return "unknown";
  std::error_code ec;
  const std::filesystem::path real = std::filesystem::canonical(info.dli_fname, ec);
  return ec ? std::string(info.dli_fname) : real.string();
}

std::string openblas_core() {
  using CoreName = char* (*)();
  auto name = reinterpret_cast<CoreName>(find_symbol("openblas_get_corename", "libopenblas.so.0"));
  const char* s = name ? name() : nullptr;
  return s ? s : "";
}

std::string describe_blas() {
  const std::string core = openblas_core();
  return blas_library() + (core.empty() ? "" : " (OpenBLAS kernels: " + core + ")");
}

}  // namespace mf
