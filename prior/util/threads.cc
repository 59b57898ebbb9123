#include "prior/util/threads.h"

#include <ATen/Parallel.h>
#include <dlfcn.h>
#ifdef _OPENMP
#include <omp.h>
#endif

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

void set_compute_threads(int n) {
  at::set_num_threads(std::max(1, n));
  keep_blas_single_threaded();
}

// libtorch's thread count is OpenMP's per-thread setting (at::get_num_threads
// is omp_get_max_threads), so setting it here leaves other threads alone.
ScopedComputeThreads::ScopedComputeThreads(int n) {
#ifdef _OPENMP
  const int current = at::get_num_threads();
  if (n > 0 && n != current) {
    saved_ = current;
    omp_set_num_threads(n);
  }
#endif
}

ScopedComputeThreads::~ScopedComputeThreads() {
#ifdef _OPENMP
  if (saved_ > 0) omp_set_num_threads(saved_);
#endif
}

void keep_blas_single_threaded() {
  // OpenBLAS's own pool stays at 1: libtorch calls BLAS from inside its
  // intra-op threads, and a second pool under them thrashes (a 40-iteration
  // sparse solve: 2.3-2.5 s with both pools at 2, 0.87 s with OpenBLAS at 1).
  using SetThreads = void (*)(int);
  if (auto set = reinterpret_cast<SetThreads>(find_symbol("openblas_set_num_threads", "libopenblas.so.0"))) set(1);
}

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
