#include "prior/util/threads.h"

#include <ATen/Parallel.h>
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <strings.h>

#include <cstdlib>
#include <filesystem>
#include <string>

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
