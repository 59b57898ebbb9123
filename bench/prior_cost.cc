// prior-cost: the cost of one latent-solver iteration for prior sizes, on this
// machine: decode 128 frames from (z_l, z_g), run the global motion predictor,
// and back-propagate a scalar to the latents only (the network frozen), as a
// solver does. Prints a markdown table of the median over repetitions.
//
//   prior-cost [--threads N] [--reps N] [--model FILE]... [--size WIDTHxLAYERS:ZL:ZG]...
//
// Without --model or --size it measures the pilot sizes of docs/PRIOR_SIZES.md.
#include <ATen/ATen.h>
#include <ATen/Parallel.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/options.h"
#include "prior/model/model_file.h"
#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/util/command_line.h"
#include "prior/util/threads.h"

namespace {

mf::RigInfo placeholder_rig(int joints) {
  // A chain skeleton of the data rig's size; cost does not depend on the shape.
  mf::RigInfo rig;
  for (int j = 0; j < joints; ++j) {
    rig.skeleton.names.push_back("j" + std::to_string(j));
    rig.skeleton.parents.push_back(j - 1);
    rig.skeleton.offsets.push_back(Eigen::Vector3d(0, j ? 0.1 : 0, 0));
  }
  rig.foot_joints = {joints - 1, joints - 2, joints - 3, joints - 4};
  rig.foot_heights.assign(4, 0.05);
  rig.foot_thresholds.assign(4, 0.05);
  return rig;
}

struct Row {
  std::string name;
  int64_t params;
  double decode_ms, step_ms;
};

Row measure(const std::string& name, const mf::NemfModel& model, int reps) {
  const mf::NemfConfig& c = model.config();
  at::Tensor frames = at::arange(c.window, at::kFloat);
  at::Tensor zl = at::randn({1, c.zl}).set_requires_grad(true);
  at::Tensor zg = at::randn({1, c.zg}).set_requires_grad(true);
  auto time_ms = [&](auto&& fn) {
    std::vector<double> t;
    fn();
    for (int i = 0; i < reps; ++i) {
      auto a = std::chrono::steady_clock::now();
      fn();
      t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
    }
    std::sort(t.begin(), t.end());
    return t[t.size() / 2];
  };
  double decode = time_ms([&] {
    at::NoGradGuard g;
    at::Tensor r = model.decode(frames, zl, zg);
  });
  double step = time_ms([&] {
    at::Tensor r = model.decode(frames, zl, zg);
    mf::GmpOutput g = model.predict_global(r);
    at::Tensor loss = r.square().sum() + model.root_positions(r, g).square().sum();
    loss.backward();
    zl.mutable_grad().reset();
    zg.mutable_grad().reset();
  });
  return {name, model.num_parameters(), decode, step};
}

// Measures every requested size and model and prints the table.
int run(int threads, int reps, std::vector<std::string> sizes, const std::vector<std::string>& models) {
  if (models.empty() && sizes.empty()) sizes = {"256x6:256:64", "384x8:384:96", "512x8:512:128", "1024x11:1024:256"};
  mf::set_compute_threads(threads);
  at::manual_seed(0);
  std::vector<Row> rows;
  for (const std::string& s : sizes) {
    mf::NemfConfig c;
    if (std::sscanf(s.c_str(), "%dx%d:%d:%d", &c.decoder_width, &c.decoder_layers, &c.zl, &c.zg) != 4) {
      throw mf::InputError("--size expects WIDTHxLAYERS:ZL:ZG, got " + s);
    }
    mf::NemfModel m(c, placeholder_rig(21));
    m.set_requires_grad(false);
    rows.push_back(measure("decoder " + s, m, reps));
  }
  for (const std::string& path : models) {
    mf::NemfModel m = mf::load_nemf(path);
    m.set_requires_grad(false);
    rows.push_back(measure(path + " (" + m.config().describe() + ")", m, reps));
  }
  std::printf("threads: %d, frames: 128, median of %d\n\n", threads, reps);
  std::printf("| model | parameters | decode (ms) | decode + GMP, backward to z (ms) |\n|---|---|---|---|\n");
  for (const Row& r : rows) {
    std::printf("| %s | %.2f M | %.2f | %.2f |\n", r.name.c_str(), r.params / 1e6, r.decode_ms, r.step_ms);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  int threads = 2, reps = 20;
  std::vector<std::string> models, sizes;
  CLI::App app{"The cost of one latent-solver iteration for prior sizes (docs/PRIOR_SIZES.md); without --model or "
               "--size it measures the pilot sizes.",
               "prior-cost"};
  mf::cli::use_tool_defaults(app);
  mf::bench::add_threads_option(app, threads);
  app.add_option("--reps", reps, "repetitions (the median is reported)")->check(mf::cli::at_least(1));
  mf::cli::repeatable(app.add_option("--model", models, "a model file to measure (repeatable)"));
  mf::cli::repeatable(app.add_option("--size", sizes, "a decoder size WIDTHxLAYERS:ZL:ZG to measure (repeatable)"));
  return mf::cli::run(app, argc, argv, [&] { return run(threads, reps, sizes, models); });
}
