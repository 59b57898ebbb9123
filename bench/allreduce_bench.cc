// allreduce-bench: the cost of the gradient all-reduce of data-parallel
// training (training/data_parallel.h) for a model of N parameters, between the
// processes of one group (docs/BENCHMARKS.md, "More than one machine: training").
//
//   allreduce-bench --parameters 5600000 --world-size 2 --rank R --master 127.0.0.1:29590 [--repeats 20]
//
// Start one process per rank; rank 0 prints the mean time per all-reduce.
#include <ATen/ATen.h>

#include <chrono>
#include <cstdio>

#include "prior/util/command_line.h"
#include "training/data_parallel.h"

int main(int argc, char** argv) {
  CLI::App app{"Times the gradient all-reduce of data-parallel training.", "allreduce-bench"};
  mf::cli::use_tool_defaults(app);
  mf::DistributedOptions d;
  int64_t parameters = 5600000;
  int repeats = 20;
  app.add_option("--parameters", parameters, "float32 gradients per step (the pilot prior: 5.6 M)");
  app.add_option("--repeats", repeats, "timed all-reduces")->check(mf::cli::at_least(1));
  app.add_option("--world-size", d.world_size, "processes");
  app.add_option("--rank", d.rank, "this process");
  app.add_option_function<std::string>("--master", [&d](const std::string& a) { d.set_master(a); }, "ADDR:PORT");
  app.add_option("--dist-timeout", d.timeout_seconds, "seconds");
  return mf::cli::run(app, argc, argv, [&] {
    mf::training::DataParallel dp(d);
    at::Tensor p = at::zeros({parameters}).set_requires_grad(true);
    p.mutable_grad() = at::ones({parameters});
    dp.average_gradients({p}, 1.0);  // warm-up: connections, buffers
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < repeats; ++i) dp.average_gradients({p}, 1.0);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / repeats;
    if (dp.writes()) {
      std::printf("%lld parameters (%.1f MB of float32 gradients), %d processes: %.1f ms per all-reduce\n",
                  static_cast<long long>(parameters), parameters * 4e-6, d.world_size, s * 1e3);
    }
    return 0;
  });
}
