// Times the matrix products the prior spends its time in, through libtorch
// (which calls the system's libblas.so.3) and through Eigen (its own kernels),
// to choose the BLAS implementation. Prints a markdown table.
//   usage: blas_bench [threads]
// Run it with LD_LIBRARY_PATH pointing at another libblas.so.3 to compare.
#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <Eigen/Core>
#include <chrono>
#include <cstdio>
#include <algorithm>
#include <vector>
#include <string>

#include "prior/util/command_line.h"
#include "prior/util/threads.h"

namespace {

template <class F>
double median_ms(F&& f, int reps) {
  std::vector<double> t;
  f();  // warm-up
  for (int i = 0; i < reps; ++i) {
    auto a = std::chrono::steady_clock::now();
    f();
    auto b = std::chrono::steady_clock::now();
    t.push_back(std::chrono::duration<double, std::milli>(b - a).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

int run(int threads) {
  mf::set_compute_threads(threads);
  Eigen::setNbThreads(threads);
  std::printf("threads: %d; BLAS: %s\n\n| m x k x n | torch mm (ms) | torch GFLOP/s | Eigen (ms) | Eigen GFLOP/s |\n|---|---|---|---|---|\n", threads, mf::describe_blas().c_str());
  const int shapes[][3] = {{2048, 782, 512}, {2048, 512, 512}, {128, 526, 256}, {4096, 1024, 1024}};
  for (auto& s : shapes) {
    int m = s[0], k = s[1], n = s[2];
    at::Tensor a = at::randn({m, k}), b = at::randn({k, n});
    double tt = median_ms([&] { at::Tensor c = at::mm(a, b); }, 15);
    Eigen::MatrixXf ea = Eigen::MatrixXf::Random(m, k), eb = Eigen::MatrixXf::Random(k, n), ec(m, n);
    double te = median_ms([&] { ec.noalias() = ea * eb; }, 15);
    double gf = 2.0 * m * k * n * 1e-9;
    std::printf("| %d x %d x %d | %.3f | %.1f | %.3f | %.1f |\n", m, k, n, tt, gf / (tt * 1e-3), te, gf / (te * 1e-3));
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  int threads = 2;
  CLI::App app{"Times the prior's matrix products through libtorch (the system's libblas.so.3) and Eigen "
               "(docs/BLAS.md).",
               "blas-bench"};
  mf::cli::use_tool_defaults(app);
  app.add_option("threads", threads, "torch and Eigen threads")->check(mf::cli::at_least(1));
  return mf::cli::run(app, argc, argv, [&] { return run(threads); });
}
