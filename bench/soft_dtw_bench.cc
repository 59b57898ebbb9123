// Times soft-DTW (tasks/reference/soft_dtw.h): forward alone and forward + backward of one
// m x n cost matrix (m = n) at each thread count, then the divergence on
// sequences the size of the re-navigation energy (128 frames, 22 joints x 3).
// Prints markdown tables (median of several runs).
//   usage: soft-dtw-bench [max_length] [threads ...]     (defaults: 4096, threads 1 2)
#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <torch/csrc/autograd/autograd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <vector>

#include "prior/util/command_line.h"
#include "prior/util/threads.h"
#include "tasks/reference/soft_dtw.h"

namespace {

double cpu_ms() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

struct Timing {
  double wall_ms, cpu_ms;  // medians; cpu = process CPU time, all threads
};

// Wall time is what a caller waits; CPU time shows the work when other
// processes share the cores (wall > cpu on one thread means waiting for a core).
template <class F>
Timing median_ms(F&& f, int reps) {
  std::vector<double> wall, cpu;
  f();  // warm-up
  for (int i = 0; i < reps; ++i) {
    const double c0 = cpu_ms();
    auto a = std::chrono::steady_clock::now();
    f();
    auto b = std::chrono::steady_clock::now();
    cpu.push_back(cpu_ms() - c0);
    wall.push_back(std::chrono::duration<double, std::milli>(b - a).count());
  }
  std::sort(wall.begin(), wall.end());
  std::sort(cpu.begin(), cpu.end());
  return {wall[wall.size() / 2], cpu[cpu.size() / 2]};
}

int run(int64_t max_length, const std::vector<int>& threads) {
  const double gamma = mf::kNemfSoftDtwGamma;
  const auto f64 = at::TensorOptions().dtype(at::kDouble);
  at::manual_seed(0);

  std::printf("soft-DTW of one m x n cost matrix (float64, uniform [0, 1) costs), gamma %.2f, B = 1\n\n", gamma);
  std::printf("| m = n | threads | forward (ms) | forward+backward (ms) | f+b CPU time (ms) | ns per cell (f+b) |"
              " saved for backward (MB) |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (int64_t len : {16, 64, 128, 256, 1024, 4096}) {
    if (len > max_length) continue;
    at::Tensor D = at::rand({len, len}, f64);
    const int reps = len <= 256 ? 51 : len <= 1024 ? 7 : 3;
    for (int t : threads) {
      mf::set_compute_threads(t);
      const Timing fwd = median_ms([&] { (void)mf::soft_dtw(D, gamma); }, reps);
      const Timing fb = median_ms(
          [&] {
            at::Tensor c = D.detach().requires_grad_(true);
            mf::soft_dtw(c, gamma).backward();
          },
          reps);
      const double mb = 3.0 * (len + 2) * (len + 2) * 8 / 1e6;
      std::printf("| %lld | %d | %.3f | %.3f | %.3f | %.1f | %.1f |\n", static_cast<long long>(len), t, fwd.wall_ms,
                  fb.wall_ms, fb.cpu_ms, fb.wall_ms * 1e6 / (double(len) * len), mb);
    }
  }

  std::printf("\nsoft-DTW divergence on sequences [B, 128, 66] vs a reference [1, 128, 66] (float32, includes the\n"
              "squared Euclidean cost matrices and their backward), gamma %.2f\n\n", gamma);
  std::printf("| B | threads | divergence forward+backward (ms) | CPU time (ms) |\n|---|---|---|---|\n");
  for (int64_t B : {1, 4}) {
    at::Tensor x = at::randn({B, 128, 66}), ref = at::randn({1, 128, 66});
    for (int t : threads) {
      mf::set_compute_threads(t);
      const Timing ms = median_ms(
          [&] {
            at::Tensor xg = x.detach().requires_grad_(true);
            mf::soft_dtw_divergence(xg, ref, gamma).sum().backward();
          },
          31);
      std::printf("| %lld | %d | %.3f | %.3f |\n", static_cast<long long>(B), t, ms.wall_ms, ms.cpu_ms);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  int64_t max_length = 4096;
  std::vector<int> threads{1, 2};
  CLI::App app{"Times soft-DTW (tasks/reference/soft_dtw.h) forward and forward + backward per sequence length and thread "
               "count, and the divergence at the re-navigation energy's size.",
               "soft-dtw-bench"};
  mf::cli::use_tool_defaults(app);
  app.add_option("max_length", max_length, "longest sequence length measured (of 16, 64, 128, 256, 1024, 4096)");
  app.add_option("threads", threads, "thread counts to measure")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->check(mf::cli::at_least(1));
  return mf::cli::run(app, argc, argv, [&] { return run(max_length, threads); });
}
