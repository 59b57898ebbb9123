// fk-cost: CPU time of forward kinematics with autograd (forward + backward
// over [1, 128, J] rotations, as in every energy evaluation of the latent
// solvers) for the library's version (one autograd node with a hand-written
// backward) against a joint-by-joint autograd reference loop. Thread CPU time, so that other jobs on the machine disturb
// it less than wall time; median over repetitions; prints a markdown table.
//
//   fk-cost [--threads N] [--reps N]
#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <torch/csrc/autograd/autograd.h>
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstdint>
#include <functional>
#include <vector>

#include "bench/options.h"
#include "prior/motion/kinematics_torch.h"
#include "prior/motion/rotations_torch.h"
#include "prior/util/command_line.h"

namespace {

double cpu_ms() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

// The joint-by-joint loop the library used before (one step per joint).
mf::FkTensors reference_fk(const std::vector<int>& parents, const at::Tensor& offsets, const at::Tensor& local,
                           const at::Tensor& root) {
  const size_t J = parents.size();
  std::vector<at::Tensor> r(J), p(J);
  r[0] = local.select(-3, 0);
  p[0] = root;
  for (size_t j = 1; j < J; ++j) {
    r[j] = mf::torch_rot::matmul3(r[parents[j]], local.select(-3, static_cast<int64_t>(j)));
    p[j] = p[parents[j]] + mf::torch_rot::matvec3(r[parents[j]], offsets[static_cast<int64_t>(j)]);
  }
  return {at::stack(p, -2), at::stack(r, -3)};
}

double median_ms(int reps, const std::function<mf::FkTensors()>& fk, const at::Tensor& local) {
  std::vector<double> t;
  for (int i = 0; i <= reps; ++i) {
    const double t0 = cpu_ms();
    mf::FkTensors out = fk();
    (out.positions.sum() + out.rotations.sum()).backward();
    local.mutable_grad().reset();
    if (i > 0) t.push_back(cpu_ms() - t0);  // the first run warms the allocator
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

int run(int threads, int reps) {
  at::set_num_threads(threads);
  // The training rig's tree: 22 joints, 8 levels (spine and arms the deepest).
  const std::vector<int> parents = {-1, 0, 1, 2, 3, 4, 0, 6, 7, 8, 0, 10, 11, 12, 13, 12, 15, 16, 17, 12, 19, 20};
  const int64_t J = static_cast<int64_t>(parents.size());
  at::manual_seed(1);
  const at::Tensor offsets = at::randn({J, 3});
  const at::Tensor local = mf::torch_rot::sixd_to_matrix(at::randn({1, 128, J, 6})).detach().requires_grad_(true);
  const at::Tensor root = at::zeros({1, 128, 3});
  const auto library = [&] { return mf::forward_kinematics(parents, offsets, local, root); };
  const auto reference = [&] { return reference_fk(parents, offsets, local, root); };
  const double lib = median_ms(reps, library, local), ref = median_ms(reps, reference, local);
  double diff = 0, grad_diff = 0;
  {
    at::NoGradGuard no_grad;
    const mf::FkTensors a = library(), b = reference();
    diff = std::max((a.positions - b.positions).abs().max().item<double>(),
                    (a.rotations - b.rotations).abs().max().item<double>());
  }
  {
    // The same weighted loss through both versions: gradients of the rotations.
    const at::Tensor wp = at::randn({1, 128, J, 3}), wr = at::randn({1, 128, J, 3, 3});
    const auto grad = [&](const std::function<mf::FkTensors()>& fk) {
      const mf::FkTensors out = fk();
      return torch::autograd::grad({(out.positions * wp).sum() + (out.rotations * wr).sum()}, {local})[0];
    };
    grad_diff = (grad(library) - grad(reference)).abs().max().item<double>();
  }
  std::printf("FK forward + backward, [1, 128, %lld] rotations, %d thread(s), median of %d (CPU ms)\n\n",
              static_cast<long long>(J), threads, reps);
  std::printf("| version | ms |\n|---|---:|\n| library (one node, hand-written backward) | %.3f |\n"
              "| joint by joint, broadcast products | %.3f |\n\nlargest difference: %.3g (outputs), %.3g "
              "(gradients of a random weighting)\n",
              lib, ref, diff, grad_diff);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  int threads = 1, reps = 50;
  CLI::App app{"CPU time of forward kinematics with autograd: the library against a joint-by-joint autograd loop.", "fk-cost"};
  mf::cli::use_tool_defaults(app);
  mf::bench::add_threads_option(app, threads);
  app.add_option("--reps", reps, "repetitions (the median is reported)")->check(mf::cli::at_least(1));
  return mf::cli::run(app, argc, argv, [&] { return run(threads, reps); });
}
