// solver-bench: quality and speed of the latent solvers (tasks/latent_solver.h)
// against interpolation, on the windows of the benchmark protocol
// (bench/protocol.h: gap filling 10 + T + 1 frames, sparse keyframes in
// 128-frame windows), with every solver setting on the command line so that
// weights and tolerances can be tuned on training clips and reported on
// validation clips. Prints markdown tables (docs/BENCHMARKS.md, "Latent solvers").
//
//   solver-bench --model FILE [--split validation|train] [--threads N] [--max-windows N]
//                [--tasks gap,sparse] [--methods interp,nemf,nemf-adam] [--lengths 5,15] [--spacings 5,10]
//                [--iterations N] [--ftol X] [--rank N] [--penalty squared|absolute] [--init NAME]
//                [--w-rot X] [--w-pos X] [--w-root-rot X] [--w-root X] [--w-prior X] [--w-skate X]
//                [--w-smooth X] [--speed N] [--out FILE]
//
// --speed N adds the speed table: N sparse windows (every 15th frame a key),
// each solved by every solver method; wall time, iterations, evaluations and
// the floor (one decoder forward + backward over 128 frames, times the
// iterations) per solve.
#include <ATen/ATen.h>
#include <ATen/Parallel.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "bench/metrics.h"
#include "bench/protocol.h"
#include "prior/data/dataset.h"
#include "prior/model/model_file.h"
#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "tasks/baselines.h"
#include "tasks/latent_solver.h"

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  if (out.empty()) throw mf::InputError("empty list '" + s + "'");
  return out;
}

std::vector<int> int_list(const std::string& s) {
  std::vector<int> out;
  for (const std::string& x : split_list(s)) out.push_back(std::atoi(x.c_str()));
  return out;
}

std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

struct Args {
  std::string model;
  std::string split = "validation";
  int threads = 1;
  int max_windows = 0;
  std::vector<std::string> tasks{"gap", "sparse"};
  std::vector<std::string> methods{"interp", "nemf", "nemf-adam"};
  std::vector<int> lengths{5, 15, 30, 45, 90};
  std::vector<int> spacings{5, 10, 15, 20, 30};
  int speed = 0;
  std::string out;
  std::map<std::string, double> numbers;  // solver overrides
  std::string penalty;
  std::string init;
};

Args parse_args(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--help") {
      std::printf("see the top of bench/solver_bench.cc\n");
      std::exit(0);
    }
    if (i + 1 >= argc) throw mf::InputError("missing value for " + flag);
    const std::string v = argv[++i];
    if (flag == "--model") a.model = v;
    else if (flag == "--split") a.split = v;
    else if (flag == "--threads") a.threads = std::max(1, std::atoi(v.c_str()));
    else if (flag == "--max-windows") a.max_windows = std::atoi(v.c_str());
    else if (flag == "--tasks") a.tasks = split_list(v);
    else if (flag == "--methods") a.methods = split_list(v);
    else if (flag == "--lengths") a.lengths = int_list(v);
    else if (flag == "--spacings") a.spacings = int_list(v);
    else if (flag == "--speed") a.speed = std::atoi(v.c_str());
    else if (flag == "--out") a.out = v;
    else if (flag == "--penalty") a.penalty = v;
    else if (flag == "--init") a.init = v;
    else if (flag.rfind("--", 0) == 0) a.numbers[flag.substr(2)] = std::atof(v.c_str());
    else throw mf::InputError("unknown argument " + flag);
  }
  if (a.model.empty()) throw mf::InputError("--model FILE is required");
  if (a.split != "validation" && a.split != "train") throw mf::InputError("--split is validation or train");
  return a;
}

mf::LatentSolverOptions solver_options(const Args& a, const std::string& method) {
  mf::LatentSolverOptions o =
      mf::default_solver_options(method == "nemf-adam" ? mf::SolverMethod::Adam : mf::SolverMethod::Lbfgs);
  std::map<std::string, double> n = a.numbers;
  auto take = [&](const char* key, auto* field) {
    auto it = n.find(key);
    if (it == n.end()) return;
    *field = static_cast<std::remove_reference_t<decltype(*field)>>(it->second);
    n.erase(it);
  };
  if (method == "nemf") {
    take("iterations", &o.max_iterations);
    take("ftol", &o.function_tolerance);
    take("ptol", &o.parameter_tolerance);
    take("rank", &o.lbfgs_rank);
    take("eigen-scaling", &o.lbfgs_eigenvalue_scaling);
    take("keyed-iterations", &o.keyed_iterations);
  } else {
    take("adam-iterations", &o.max_iterations);
    take("adam-tol", &o.adam_tolerance);
    n.erase("iterations");
    n.erase("ftol");
    n.erase("ptol");
    n.erase("rank");
    n.erase("eigen-scaling");
    n.erase("keyed-iterations");
  }
  n.erase("adam-iterations");
  n.erase("adam-tol");
  take("w-rot", &o.weights.rotation);
  take("w-pos", &o.weights.position);
  take("w-root-rot", &o.weights.root_orientation);
  take("w-root", &o.weights.root_translation);
  take("w-prior", &o.weights.latent_prior);
  take("w-skate", &o.weights.foot_skating);
  take("w-smooth", &o.weights.smoothness);
  take("w-effector", &o.weights.effector);
  if (!n.empty()) throw mf::InputError("unknown option --" + n.begin()->first);
  if (a.penalty == "absolute") o.weights.penalty = mf::Penalty::Absolute;
  else if (!a.penalty.empty() && a.penalty != "squared") throw mf::InputError("--penalty is squared or absolute");
  if (!a.init.empty()) o.initializer = mf::make_initializer(a.init);
  return o;
}

std::string describe(const mf::LatentSolverOptions& o) {
  std::ostringstream s;
  const mf::EnergyWeights& w = o.weights;
  s << (o.method == mf::SolverMethod::Adam ? "Adam" : "L-BFGS") << ", max iterations "
    << (o.max_iterations ? std::to_string(o.max_iterations) : std::string("default"));
  if (o.method == mf::SolverMethod::Lbfgs)
    s << ", ftol " << o.function_tolerance << ", rank " << o.lbfgs_rank << ", keys-only stage " << o.keyed_iterations;
  s << "; weights: rotation " << w.rotation << ", position " << w.position << ", root orientation "
    << w.root_orientation << ", root translation " << w.root_translation << ", latent prior " << w.latent_prior
    << ", foot skating " << w.foot_skating << ", smoothness " << w.smoothness << "; penalty "
    << (w.penalty == mf::Penalty::Squared ? "squared" : "absolute");
  return s.str();
}

struct Row {
  int parameter = 0;
  mf::bench::MetricSummary metrics;
  double ms = 0.0, iterations = 0.0, evaluations = 0.0, raw_rot_deg = 0.0, raw_root_cm = 0.0, energy_ratio = 0.0;
};

// One method on one protocol row.
struct Runner {
  const mf::NemfModel& model;
  const Args& args;

  mf::Motion solve(const std::string& method, const mf::Motion& input, const std::vector<int>& known, Row* row) const {
    if (method == "interp") {
      const auto t0 = Clock::now();
      mf::Motion out = mf::interpolate_motion(input, known);
      row->ms += ms_since(t0);
      return out;
    }
    mf::CompletionReport report;
    const auto t0 = Clock::now();
    mf::Motion out = mf::complete_motion(model, input, mf::MotionConstraints::full_pose(known),
                                         solver_options(args, method), {}, &report);
    row->ms += ms_since(t0);
    row->iterations += report.iterations;
    for (const auto& w : report.windows) row->evaluations += w.evaluations;
    row->raw_rot_deg += report.raw_known.rotation_mean_deg;
    row->raw_root_cm += report.raw_known.root_mean_cm;
    double e0 = 0, e1 = 0;
    for (const auto& w : report.windows) {
      e0 += w.initial_energy;
      e1 += w.final_energy;
    }
    row->energy_ratio += e0 > 0 ? e1 / e0 : 0.0;
    return out;
  }
};

std::string table(const std::string& title, const char* param, const std::vector<Row>& rows) {
  std::ostringstream s;
  s << title << "\n\n| " << param
    << " | windows | L2P | L2Q | NPSS | MPJPE (cm) | skating (cm) | skating GT (cm) | raw known rot (deg) | raw known "
       "root (cm) | E final / E0 | iterations | evaluations | ms / window |\n"
    << "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Row& r : rows) {
    const int n = std::max(1, r.metrics.windows);
    s << "| " << r.parameter << " | " << r.metrics.windows << " | " << fixed(r.metrics.l2p, 3) << " | "
      << fixed(r.metrics.l2q, 3) << " | " << fixed(r.metrics.npss, 4) << " | " << fixed(r.metrics.mpjpe_cm, 2) << " | "
      << fixed(r.metrics.skating_cm, 3) << " | " << fixed(r.metrics.truth_skating_cm, 3) << " | "
      << fixed(r.raw_rot_deg / n, 2) << " | " << fixed(r.raw_root_cm / n, 2) << " | " << fixed(r.energy_ratio / n, 3)
      << " | " << fixed(r.iterations / n, 1) << " | " << fixed(r.evaluations / n, 1) << " | " << fixed(r.ms / n, 1)
      << " |\n";
  }
  return s.str();
}

// Median wall time of one decoder forward + backward to the latents over 128 frames.
double decoder_step_ms(const mf::NemfModel& model) {
  const mf::NemfConfig& c = model.config();
  at::Tensor frames = at::arange(c.window, at::kFloat);
  at::Tensor zl = at::zeros({1, c.zl}).requires_grad_(true), zg = at::zeros({1, c.zg}).requires_grad_(true);
  std::vector<double> t;
  for (int i = 0; i < 21; ++i) {
    const auto t0 = Clock::now();
    at::Tensor r = model.decode(frames, zl, zg);
    r.sum().backward();
    zl.mutable_grad().reset();
    zg.mutable_grad().reset();
    if (i > 0) t.push_back(ms_since(t0));
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

int run(int argc, char** argv) {
  const Args args = parse_args(argc, argv);
  at::set_num_threads(args.threads);
  std::string command = "solver-bench";
  for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];

  mf::NemfModel model = mf::load_nemf(args.model);
  model.set_requires_grad(false);
  mf::DatasetOptions data_options;
  data_options.source = mf::default_train_archive();
  data_options.cache_dir = mf::default_cache_dir();
  const mf::Dataset data = mf::load_dataset(data_options);
  const mf::bench::EvalStats stats = mf::bench::compute_eval_stats(data.train);
  const std::vector<mf::Clip>& clips = args.split == "train" ? data.train : data.validation;

  std::ostringstream md;
  auto emit = [&](const std::string& text) {
    std::cout << text << std::flush;
    md << text;
  };
  emit("## solver-bench\n\n- command: `" + command + "`\n- model: " + args.model + " (" + model.config().describe() +
       ")\n- split: " + args.split + " (" + std::to_string(clips.size()) + " clips)\n- torch threads: " +
       std::to_string(at::get_num_threads()) + "\n");
  for (const std::string& m : args.methods) {
    if (m != "interp") emit("- `" + m + "`: " + describe(solver_options(args, m)) + "\n");
  }
  emit("\n");

  const Runner runner{model, args};
  mf::bench::ProtocolOptions protocol;
  const Eigen::Vector3d forward = model.rig().root_forward;
  for (const std::string& task : args.tasks) {
    for (const std::string& method : args.methods) {
      std::vector<Row> rows;
      if (task == "gap") {
        for (int T : args.lengths) {
          const int length = protocol.context + T + 1, a = protocol.context, b = protocol.context + T;
          const auto windows =
              mf::bench::cap_windows(mf::bench::protocol_windows(clips, length, protocol.stride), args.max_windows);
          std::vector<int> evaluated, known;
          for (int f = 0; f < length; ++f) (f >= a && f < b ? evaluated : known).push_back(f);
          mf::bench::MetricAccumulator acc(stats);
          Row row;
          row.parameter = T;
          for (const mf::Window& w : windows) {
            const mf::Motion truth = mf::bench::canonicalise(
                clips[w.clip].motion.slice(w.start, w.start + length), protocol.context - 1, forward);
            const mf::Motion input = mf::bench::hide_unknown_frames(truth, known);
            acc.add(truth, runner.solve(method, input, known, &row), evaluated, known);
          }
          row.metrics = acc.summary();
          rows.push_back(row);
          std::cerr << "gap " << T << " " << method << " done\n";
        }
        emit(table("#### Gap filling, `" + method + "`", "T", rows) + "\n");
      } else if (task == "sparse") {
        const int length = protocol.sparse_window;
        const auto windows =
            mf::bench::cap_windows(mf::bench::protocol_windows(clips, length, protocol.stride), args.max_windows);
        for (int k : args.spacings) {
          const std::vector<int> keys = mf::bench::sparse_keyframes(length, k);
          std::vector<int> evaluated;
          for (int f = 0; f < length; ++f) {
            if (!std::binary_search(keys.begin(), keys.end(), f)) evaluated.push_back(f);
          }
          mf::bench::MetricAccumulator acc(stats);
          Row row;
          row.parameter = k;
          for (const mf::Window& w : windows) {
            const mf::Motion truth =
                mf::bench::canonicalise(clips[w.clip].motion.slice(w.start, w.start + length), 0, forward);
            const mf::Motion input = mf::bench::hide_unknown_frames(truth, keys);
            acc.add(truth, runner.solve(method, input, keys, &row), evaluated, keys);
          }
          row.metrics = acc.summary();
          rows.push_back(row);
          std::cerr << "sparse " << k << " " << method << " done\n";
        }
        emit(table("#### Sparse keyframes (128 frames), `" + method + "`", "k", rows) + "\n");
      } else {
        throw mf::InputError("unknown task " + task);
      }
    }
  }

  if (args.speed > 0) {
    const double step = decoder_step_ms(model);
    const auto windows = mf::bench::cap_windows(mf::bench::protocol_windows(clips, 128, 40), args.speed);
    const std::vector<int> keys = mf::bench::sparse_keyframes(128, 15);
    std::ostringstream s;
    s << "#### Speed: sparse keyframes every 15 frames, 128-frame windows, " << windows.size() << " windows, "
      << at::get_num_threads() << " torch thread(s)\n\n"
      << "Decoder forward + backward over 128 frames: " << fixed(step, 2) << " ms (median of 20).\n\n"
      << "| method | ms / solve (mean) | ms / solve (median) | iterations | evaluations | floor: decoder f+b x "
         "iterations (ms) | L2P |\n|---|---:|---:|---:|---:|---:|---:|\n";
    std::map<std::string, double> mean_ms;
    for (const std::string& method : args.methods) {
      if (method == "interp") continue;
      std::vector<double> ms;
      double iters = 0, evals = 0;
      mf::bench::MetricAccumulator acc(stats);
      std::vector<int> evaluated;
      for (int f = 0; f < 128; ++f) {
        if (!std::binary_search(keys.begin(), keys.end(), f)) evaluated.push_back(f);
      }
      for (const mf::Window& w : windows) {
        const mf::Motion truth = mf::bench::canonicalise(clips[w.clip].motion.slice(w.start, w.start + 128), 0, forward);
        const mf::Motion input = mf::bench::hide_unknown_frames(truth, keys);
        mf::CompletionReport report;
        const auto t0 = Clock::now();
        mf::Motion out = mf::complete_motion(model, input, mf::MotionConstraints::full_pose(keys),
                                             solver_options(args, method), {}, &report);
        ms.push_back(ms_since(t0));
        iters += report.iterations;
        for (const auto& r : report.windows) evals += r.evaluations;
        acc.add(truth, out, evaluated, keys);
      }
      const double n = std::max<size_t>(1, ms.size());
      double sum = 0;
      for (double x : ms) sum += x;
      std::vector<double> sorted = ms;
      std::sort(sorted.begin(), sorted.end());
      mean_ms[method] = sum / n;
      s << "| " << method << " | " << fixed(sum / n, 0) << " | " << fixed(sorted.empty() ? 0 : sorted[sorted.size() / 2], 0)
        << " | " << fixed(iters / n, 1) << " | " << fixed(evals / n, 1) << " | " << fixed(step * iters / n, 0) << " | "
        << fixed(acc.summary().l2p, 3) << " |\n";
    }
    if (mean_ms.count("nemf") && mean_ms.count("nemf-adam") && mean_ms["nemf"] > 0) {
      s << "\nSpeed-up of `nemf` over `nemf-adam`: " << fixed(mean_ms["nemf-adam"] / mean_ms["nemf"], 1) << "x\n";
    }
    emit(s.str() + "\n");
  }
  if (!args.out.empty()) {
    std::ofstream f(args.out);
    f << md.str();
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const mf::InputError& e) {
    std::fprintf(stderr, "solver-bench: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "solver-bench: internal error: %s\n", e.what());
    return 1;
  }
}
