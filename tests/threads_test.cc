#include "prior/util/threads.h"

#include <ATen/Parallel.h>
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <strings.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <set>
#include <string>
#include <thread>

namespace mf {
namespace {

TEST(Threads, SetComputeThreadsSizesLibtorchAndKeepsOpenBlasSerial) {
  using GetThreads = int (*)();
  auto openblas = reinterpret_cast<GetThreads>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  for (int n : {1, 2}) {
    set_compute_threads(n);
    EXPECT_EQ(at::get_num_threads(), n);
    if (openblas) {
      EXPECT_EQ(openblas(), 1);
    }
  }
  set_compute_threads(0);  // clamped, never an invalid pool size
  EXPECT_EQ(at::get_num_threads(), 1);
}

// The thread ids an at::parallel_for over two chunks ran them on.
std::set<std::thread::id> chunk_threads() {
  std::mutex m;
  std::set<std::thread::id> ids;
  at::parallel_for(0, 2, 1, [&](int64_t, int64_t) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // both chunks in flight at once
    std::lock_guard<std::mutex> lock(m);
    ids.insert(std::this_thread::get_id());
  });
  return ids;
}

TEST(Threads, OurParallelLoopsRunInParallelAndTheScopeLimitsThem) {
#if !defined(_OPENMP) && defined(__clang__)
  GTEST_SKIP() << "built without OpenMP (clang): at::parallel_for runs serially here";
#elif !defined(_OPENMP)
  FAIL() << "a GCC build without -fopenmp: every at::parallel_for of ours runs on one thread";
#else
  // at::parallel_for is an inline OpenMP loop: a build that loses -fopenmp
  // (CMakeLists.txt) runs every loop of ours on one thread.
  set_compute_threads(2);
  EXPECT_EQ(chunk_threads().size(), 2u);
  {
    ScopedComputeThreads one(1);
    EXPECT_EQ(at::get_num_threads(), 1);
    EXPECT_EQ(chunk_threads().size(), 1u);
    int other = 0;  // another thread keeps its own count
    std::thread([&] { other = at::get_num_threads(); }).join();
    EXPECT_EQ(other, 2);
    ScopedComputeThreads same(0);  // changes nothing
    EXPECT_EQ(at::get_num_threads(), 1);
  }
  EXPECT_EQ(at::get_num_threads(), 2);
  EXPECT_EQ(chunk_threads().size(), 2u);
  set_compute_threads(1);
#endif
}

// The matrix products go to the libblas.so.3 alternative, not to ATLAS's
// libf77blas.so.3 that Ceres drags in (CMakeLists.txt, MF_BLAS_RUNTIME). This
// binary links Ceres, so a lost link order shows here.
TEST(Threads, MatrixProductsUseTheSelectedBlas) {
  const std::string blas = blas_library();
  ASSERT_NE(blas, "unknown");
  EXPECT_EQ(blas.find("f77blas"), std::string::npos) << blas;
  std::error_code ec;
  const auto selected = std::filesystem::canonical("/usr/lib/x86_64-linux-gnu/libblas.so.3", ec);
  if (ec) GTEST_SKIP() << "no /usr/lib/x86_64-linux-gnu/libblas.so.3 on this machine";
  EXPECT_EQ(blas, selected.string());
}

// OpenBLAS picks its kernels when it is loaded, from the CPU or from
// OPENBLAS_CORETYPE; openblas_core() names the ones it runs (benchmark headers
// print it, docs/BLAS.md).
TEST(Threads, NamesTheOpenBlasKernels) {
  const std::string core = openblas_core();
  if (blas_library().find("openblas") == std::string::npos) {
    EXPECT_EQ(core, "") << blas_library();
    GTEST_SKIP() << "the BLAS is not OpenBLAS: " << blas_library();
  }
  ASSERT_NE(core, "");
  EXPECT_NE(describe_blas().find("(OpenBLAS kernels: " + core + ")"), std::string::npos) << describe_blas();
  if (const char* chosen = std::getenv("OPENBLAS_CORETYPE")) {
    EXPECT_EQ(strcasecmp(core.c_str(), chosen), 0) << "OPENBLAS_CORETYPE=" << chosen << ", kernels " << core;
  }
}

}  // namespace
}  // namespace mf
