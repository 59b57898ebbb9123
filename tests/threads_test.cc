#include "prior/util/threads.h"

#include <ATen/Parallel.h>
#include <dlfcn.h>
#include <gtest/gtest.h>

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
    if (openblas) EXPECT_EQ(openblas(), 1);
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

}  // namespace
}  // namespace mf
