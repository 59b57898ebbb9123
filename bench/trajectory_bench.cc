// trajectory-bench: the latent solver's trajectory energy (tasks/energies.h,
// EnergyWeights::trajectory and trajectory_facing) on the gap-filling windows
// of the benchmark protocol (bench/protocol.h: 10 context frames, a gap of T,
// the target frame), with the ground truth's trajectory (root ground position
// and facing, trajectory_features()) as a row on every gap frame. Per gap,
// start (make_initializer() name) and weight pair it reports L2P, L2Q, NPSS,
// foot skating and how closely the root follows the rows (mean and max ground
// distance, cm; mean and max facing error, degrees), and the same for the
// solver without a trajectory and for interpolation; it chose the default
// weights (docs/CONSTRAINTS.md, "Trajectory").
//
//   trajectory-bench [--model FILE] [--split validation|train] [--max-windows N] [--threads N]
//                    [--gaps 30,60] [--starts interp-encoder,detail-encoder]
//                    [--weights 10] [--facing-weights 1] [--source PATH] [--cache-dir DIR] [--out FILE]
#include <ATen/Parallel.h>

#include <chrono>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bench/metrics.h"
#include "bench/options.h"
#include "bench/protocol.h"
#include "bench/text.h"
#include "prior/model/model_file.h"
#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/util/command_line.h"
#include "prior/util/threads.h"
#include "tasks/baselines.h"
#include "tasks/constraint_report.h"
#include "tasks/latent_solver.h"
#include "tasks/model_rig.h"

namespace {

using mf::bench::fixed;

struct Args {
  std::string model;
  mf::bench::DataSource data;
  mf::bench::SplitChoice split;
  mf::bench::TransformerFiles transformers;
  int threads = 1;
  std::vector<int> gaps{30, 60};
  std::vector<std::string> starts{"interp-encoder", "detail-encoder"};
  std::vector<double> weights{mf::EnergyWeights{}.trajectory};
  std::vector<double> facing_weights{mf::EnergyWeights{}.trajectory_facing};
  std::string out;
};

void add_options(CLI::App& app, Args& a) {
  app.add_option("--model", a.model, "the prior (default: the default model)");
  mf::bench::add_data_options(app, a.data);
  mf::bench::add_split_options(app, a.split);
  mf::bench::add_transformer_options(app, a.transformers);
  mf::bench::add_threads_option(app, a.threads);
  mf::bench::add_list_option(app, "--gaps", a.gaps, "gap lengths (default 30,60)");
  app.add_option("--starts", a.starts, "the solver's starts, make_initializer() names (default interp-encoder,detail-encoder)")
      ->delimiter(',');
  app.add_option("--weights", a.weights, "trajectory (ground position) weights to try (default: the default)")
      ->delimiter(',');
  app.add_option("--facing-weights", a.facing_weights, "trajectory_facing weights to try (default: the default)")
      ->delimiter(',');
  app.add_option("--out", a.out, "also write the markdown to FILE");
}

// The ground truth's trajectory rows at `frames` (the rig's forward axis).
std::vector<mf::TrajectoryPoint> truth_trajectory(const mf::Motion& truth, const std::vector<int>& frames,
                                                  const Eigen::Vector3d& root_forward) {
  std::vector<mf::TrajectoryPoint> rows;
  for (int f : frames) {
    const Eigen::Vector3d fwd = truth.rotation(f, 0).normalized() * root_forward;
    const double n = std::hypot(fwd.x(), fwd.z());
    rows.push_back({f, truth.root_positions[f].x(), truth.root_positions[f].z(), fwd.x() / n, fwd.z() / n});
  }
  return rows;
}

// What one configuration measured over the windows.
struct Row {
  std::string name;
  mf::bench::MetricAccumulator metrics;
  double cm_sum = 0.0, cm_max = 0.0, deg_sum = 0.0, deg_max = 0.0, seconds = 0.0;
  int windows = 0;
  explicit Row(std::string n, const mf::bench::EvalStats& stats) : name(std::move(n)), metrics(stats) {}
  void add(const mf::Motion& truth, const mf::Motion& out, const mf::MotionConstraints& with_rows,
           const std::vector<int>& evaluated, const std::vector<int>& known, const Eigen::Vector3d& fwd, double s) {
    metrics.add(truth, out, evaluated, known);
    const mf::TrajectoryError e = mf::trajectory_error(out, with_rows, fwd);
    cm_sum += e.mean_cm;
    cm_max = std::max(cm_max, e.max_cm);
    deg_sum += e.facing_mean_deg;
    deg_max = std::max(deg_max, e.facing_max_deg);
    seconds += s;
    ++windows;
  }
  std::string cells(int T) const {
    const mf::bench::MetricSummary m = metrics.summary();
    const int W = std::max(windows, 1);
    return "| " + std::to_string(T) + " | " + std::to_string(windows) + " | " + name + " | " + fixed(m.l2p, 3) + " | " +
           fixed(m.l2q, 3) + " | " + fixed(m.npss, 4) + " | " + fixed(m.skating_cm, 3) + " | " + fixed(cm_sum / W, 2) +
           " / " + fixed(cm_max, 2) + " | " + fixed(deg_sum / W, 2) + " / " + fixed(deg_max, 2) + " | " +
           fixed(seconds / W, 2) + " |\n";
  }
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The configurations: interpolation, then per start the solver without a
// trajectory and with each weight pair.
std::vector<Row> make_rows(const Args& args, const mf::bench::EvalStats& stats) {
  std::vector<Row> rows{Row("interpolation", stats)};
  for (const std::string& s : args.starts) {
    rows.emplace_back(s + ", no trajectory", stats);
    for (double w : args.weights)
      for (double f : args.facing_weights) rows.emplace_back(s + ", weights " + fixed(w, 1) + " / " + fixed(f, 1), stats);
  }
  return rows;
}

std::string run_gap(const Args& args, int T, const std::vector<mf::Clip>& clips, const mf::bench::EvalStats& stats,
                    const mf::TaskContext& ctx) {
  const int context = 10, length = context + T + 1, a = context, b = context + T;
  const std::vector<mf::Window> windows =
      mf::bench::cap_windows(mf::bench::protocol_windows(clips, length, 40), args.split.max_windows);
  std::vector<int> evaluated, known;
  for (int f = 0; f < length; ++f) (f >= a && f < b ? evaluated : known).push_back(f);
  const Eigen::Vector3d fwd = ctx.model->rig().root_forward;
  std::vector<Row> rows = make_rows(args, stats);
  for (const mf::Window& w : windows) {
    const mf::Motion truth = mf::bench::canonicalise(clips[w.clip].motion.slice(w.start, w.start + length), context - 1);
    const mf::Motion input = mf::bench::hide_unknown_frames(truth, known);
    mf::MotionConstraints plain = mf::MotionConstraints::full_pose(known), traj = plain;
    traj.trajectory = truth_trajectory(truth, evaluated, fwd);
    auto t0 = std::chrono::steady_clock::now();
    const mf::Motion lerp = mf::interpolate_motion(input, known);
    size_t r = 0;
    rows[r++].add(truth, lerp, traj, evaluated, known, fwd, seconds_since(t0));
    for (const std::string& s : args.starts) {
      mf::LatentSolverOptions o = mf::default_solver_options();
      o.initializer = mf::make_initializer(s, ctx);
      t0 = std::chrono::steady_clock::now();
      const mf::Motion base = mf::complete_motion(*ctx.model, input, plain, o, ctx);
      rows[r++].add(truth, base, traj, evaluated, known, fwd, seconds_since(t0));
      for (double wt : args.weights) {
        for (double wf : args.facing_weights) {
          o.weights.trajectory = wt;
          o.weights.trajectory_facing = wf;
          t0 = std::chrono::steady_clock::now();
          const mf::Motion out = mf::complete_motion(*ctx.model, input, traj, o, ctx);
          rows[r++].add(truth, out, traj, evaluated, known, fwd, seconds_since(t0));
        }
      }
    }
  }
  std::string text;
  for (const Row& row : rows) text += row.cells(T);
  return text;
}

int run(Args& args, const std::string& command) {
  if (args.model.empty()) args.model = mf::default_model_path();
  if (args.model.empty()) throw mf::InputError("no default model: pass --model FILE");
  mf::set_compute_threads(args.threads);
  mf::TaskContext ctx;
  auto model = std::make_shared<mf::NemfModel>(mf::load_nemf(args.model));
  model->set_requires_grad(false);
  ctx.model = model;
  mf::bench::load_transformers(args.transformers, args.model, &ctx, false);
  const mf::Dataset data = mf::bench::load_data(args.data, false);
  const std::vector<mf::Clip>& clips = args.split.clips(data);
  const mf::bench::EvalStats stats = mf::bench::compute_eval_stats(data.train);

  std::ostringstream md;
  md << "## trajectory-bench\n\n- command: `" << command << "`\n- model: " << args.model << "\n- "
     << args.split.split << " split, torch threads: " << at::get_num_threads()
     << "\n- trajectory rows: the ground truth's on every gap frame; weights: trajectory / trajectory_facing\n\n"
     << "| gap | windows | solution | L2P | L2Q | NPSS | skating (cm) | ground distance mean / max (cm) | "
        "facing mean / max (deg) | s / window |\n"
     << "|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|\n";
  std::cout << md.str() << std::flush;
  for (int T : args.gaps) {
    const std::string rows = run_gap(args, T, clips, stats, ctx);
    std::cout << rows << std::flush;
    md << rows;
  }
  if (!args.out.empty()) std::ofstream(args.out) << md.str();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  CLI::App app{"The latent solver's trajectory energy on the validation clips (docs/CONSTRAINTS.md, \"Trajectory\").",
               "trajectory-bench"};
  mf::cli::use_tool_defaults(app);
  add_options(app, args);
  return mf::cli::run(app, argc, argv,
                      [&] { return run(args, mf::bench::command_line("trajectory-bench", argc, argv)); });
}
