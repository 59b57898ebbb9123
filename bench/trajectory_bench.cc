// trajectory-bench: the latent solver's trajectory energy (tasks/reference/energies.h,
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
// With --paths it measures instead how closely methods (by name, through
// run_constrained) follow trajectories that are not the ground truth: NeMF's
// test paths drawn between the last context frame's root and the target's
// (a straight line, loops of 0.5 m and 1.5 m radius, a sinusoid of 0.5 m
// amplitude; see test_path()), reporting the root's ground and facing error and
// the foot skating against the ground truth's on the same frames.
//
//   trajectory-bench [--model FILE] [--split validation|train] [--max-windows N] [--threads N]
//                    [--gaps 30,60] [--starts interp-encoder,detail-encoder]
//                    [--weights 10] [--facing-weights 1] [--source PATH] [--cache-dir DIR] [--out FILE]
//                    [--paths line,loop-0.5,loop-1.5,sine --methods refine,nemf-refine]
#include <ATen/Parallel.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "bench/metrics.h"
#include "bench/options.h"
#include "bench/protocol.h"
#include "bench/text.h"
#include "prior/runtime/nemf_runtime.h"
#include "prior/motion/errors.h"
#include "tasks/constraints/constraint_report.h"
#include "tasks/constraints/interpolation_fill.h"
#include "tasks/latent/latent_solver.h"
#include "tasks/methods/jobs.h"

namespace {

using mf::bench::fixed;

struct Args : mf::bench::ModelBenchOptions {
  std::vector<int> gaps{30, 60};
  std::vector<std::string> starts{"interp-encoder", "detail-encoder"};
  std::vector<double> weights{mf::EnergyWeights{}.trajectory};
  std::vector<double> facing_weights{mf::EnergyWeights{}.trajectory_facing};
  std::vector<std::string> paths;
  std::vector<std::string> methods{"refine", "nemf-refine"};
  std::string out;
};

void add_options(CLI::App& app, Args& a) {
  mf::bench::add_model_bench_options(app, a);
  mf::bench::add_list_option(app, "--gaps", a.gaps, "gap lengths (default 30,60)");
  app.add_option("--starts", a.starts, "the solver's starts, make_initializer() names (default interp-encoder,detail-encoder)")
      ->delimiter(',');
  app.add_option("--weights", a.weights, "trajectory (ground position) weights to try (default: the default)")
      ->delimiter(',');
  app.add_option("--facing-weights", a.facing_weights, "trajectory_facing weights to try (default: the default)")
      ->delimiter(',');
  app.add_option("--paths", a.paths,
                 "instead: follow test paths (line, loop-0.5, loop-1.5, sine) drawn between the known roots")
      ->delimiter(',');
  app.add_option("--methods", a.methods, "with --paths: the methods (default refine,nemf-refine)")->delimiter(',');
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

// A test path for the gap frames a..b-1: from the root's ground position at
// frame a-1 (A) to the one at frame b (B), progress s = (f - a + 1) / (b - a + 1)
// uniform in time. "line": A + s (B - A); "sine": the line plus 0.5 m * sin(2 pi s)
// to its left; "loop-R": the line plus one full circle of radius R metres that
// leaves A along the line and turns left, R (sin(2 pi s) d + (1 - cos(2 pi s)) n),
// with d the unit direction A -> B (the facing at A when A and B are less than
// 20 cm apart) and n its left normal. The facing is the path's unit tangent,
// turned toward the known facing at frame a-1 over the first 15 frames and
// toward the target's over the last 15 (raised-cosine weights), so that the
// path does not contradict the keys that bound it.
std::vector<mf::TrajectoryPoint> test_path(const std::string& shape, const mf::Motion& truth, int a, int b,
                                           const Eigen::Vector3d& root_forward) {
  const Eigen::Vector2d A(truth.root_positions[a - 1].x(), truth.root_positions[a - 1].z());
  const Eigen::Vector2d B(truth.root_positions[b].x(), truth.root_positions[b].z());
  const Eigen::Vector3d f3 = truth.rotation(a - 1, 0).normalized() * root_forward;
  const Eigen::Vector3d fb = truth.rotation(b, 0).normalized() * root_forward;
  const double yaw_a = std::atan2(f3.x(), f3.z()), yaw_b = std::atan2(fb.x(), fb.z());
  // Signed angle from y to x, in (-pi, pi].
  auto turn = [](double x, double y) { return std::remainder(x - y, 2.0 * M_PI); };
  auto near = [](int frames) { return frames >= 15 ? 0.0 : 0.5 * (1.0 + std::cos(M_PI * frames / 15.0)); };
  Eigen::Vector2d d = B - A;
  d = d.norm() >= 0.2 ? Eigen::Vector2d(d.normalized()) : Eigen::Vector2d(Eigen::Vector2d(f3.x(), f3.z()).normalized());
  // Left of d when y is up and the ground is (x, z): rotating forward +z by +90 deg about y gives +x.
  const Eigen::Vector2d n(d.y(), -d.x());
  double radius = 0.0, amplitude = 0.0;
  if (shape == "sine") {
    amplitude = 0.5;
  } else if (shape.rfind("loop-", 0) == 0) {
    radius = std::stod(shape.substr(5));
  } else if (shape != "line") {
    throw mf::InputError("unknown test path '" + shape + "' (line, loop-R with R in metres, sine)");
  }
  const double two_pi = 2.0 * M_PI;
  std::vector<mf::TrajectoryPoint> rows;
  for (int f = a; f < b; ++f) {
    const double s = static_cast<double>(f - a + 1) / (b - a + 1);
    const Eigen::Vector2d p = A + s * (B - A) + radius * (std::sin(two_pi * s) * d + (1 - std::cos(two_pi * s)) * n) +
                              amplitude * std::sin(two_pi * s) * n;
    Eigen::Vector2d v = (B - A) + radius * two_pi * (std::cos(two_pi * s) * d + std::sin(two_pi * s) * n) +
                        amplitude * two_pi * std::cos(two_pi * s) * n;
    if (v.norm() < 1e-6) v = d;
    double yaw = std::atan2(v.x(), v.y());
    yaw += near(f - a + 1) * turn(yaw_a, yaw) + near(b - f) * turn(yaw_b, yaw);
    rows.push_back({f, p.x(), p.y(), std::sin(yaw), std::cos(yaw)});
  }
  return rows;
}

// What one method did on one path over the windows of one gap.
struct PathRow {
  std::string path, method;
  mf::bench::MetricAccumulator metrics;
  double cm_sum = 0.0, cm_max = 0.0, deg_sum = 0.0, deg_max = 0.0, seconds = 0.0;
  int windows = 0, failed = 0;
  PathRow(std::string p, std::string m, const mf::bench::EvalStats& stats)
      : path(std::move(p)), method(std::move(m)), metrics(stats) {}
  std::string cells(int T) const {
    const mf::bench::MetricSummary m = metrics.summary();
    const int W = std::max(windows, 1);
    return "| " + std::to_string(T) + " | " + path + " | " + method + " | " + std::to_string(windows) + " | " +
           std::to_string(failed) + " | " + fixed(cm_sum / W, 2) + " / " + fixed(cm_max, 2) + " | " +
           fixed(deg_sum / W, 2) + " / " + fixed(deg_max, 2) + " | " + fixed(m.skating_cm, 3) + " | " +
           fixed(m.truth_skating_cm, 3) + " | " + fixed(seconds / W, 2) + " |\n";
  }
};

std::string run_paths(const Args& args, int T, const std::vector<mf::Clip>& clips, const mf::bench::EvalStats& stats,
                      const mf::TaskContext& ctx) {
  const int context = 10, length = context + T + 1, a = context, b = context + T;
  const std::vector<mf::Window> windows =
      mf::bench::cap_windows(mf::bench::protocol_windows(clips, length, 40), args.split.max_windows);
  std::vector<int> evaluated, known;
  for (int f = 0; f < length; ++f) (f >= a && f < b ? evaluated : known).push_back(f);
  const Eigen::Vector3d fwd = ctx.model->rig().root_forward;
  std::vector<PathRow> rows;
  for (const std::string& p : args.paths)
    for (const std::string& m : args.methods) rows.emplace_back(p, m, stats);
  for (const mf::Window& w : windows) {
    const mf::Motion truth = mf::bench::canonicalise(clips[w.clip].motion.slice(w.start, w.start + length), context - 1);
    const mf::Motion input = mf::bench::hide_unknown_frames(truth, known);
    for (PathRow& row : rows) {
      mf::MotionConstraints c = mf::MotionConstraints::full_pose(known);
      c.trajectory = test_path(row.path, truth, a, b, fwd);
      const auto t0 = std::chrono::steady_clock::now();
      try {
        const mf::Motion out = mf::run_constrained(input, c, row.method, 0, ctx).motions.front();
        row.seconds += seconds_since(t0);
        row.metrics.add(truth, out, evaluated, known);
        const mf::TrajectoryError e = mf::trajectory_error(out, c, fwd);
        row.cm_sum += e.mean_cm;
        row.cm_max = std::max(row.cm_max, e.max_cm);
        row.deg_sum += e.facing_mean_deg;
        row.deg_max = std::max(row.deg_max, e.facing_max_deg);
        ++row.windows;
      } catch (const mf::InputError& e) {
        std::cerr << "gap " << T << ", " << row.path << ", " << row.method << ": " << e.what() << "\n";
        ++row.failed;
      }
    }
  }
  std::string text;
  for (const PathRow& row : rows) text += row.cells(T);
  return text;
}

int run(Args& args, const std::string& command) {
  const mf::bench::BenchContext bench = mf::bench::load_bench_context(args);
  const std::vector<mf::Clip>& clips = args.split.clips(bench.data);

  // With --paths the tables of the test paths, else those of the ground truth's trajectory.
  const bool paths = !args.paths.empty();
  std::ostringstream md;
  md << "## trajectory-bench" << (paths ? ": test paths" : "") << "\n\n- command: `" << command
     << "`\n- model: " << bench.model_path << "\n- " << args.split.split
     << " split, torch threads: " << at::get_num_threads();
  if (paths) {
    md << "\n- skating: of the result and of the ground truth on the same frames\n\n"
       << "| gap | path | method | windows | failed | ground distance mean / max (cm) | facing mean / max (deg) | "
          "skating (cm) | ground truth's skating (cm) | s / window |\n"
       << "|---:|---|---|---:|---:|---:|---:|---:|---:|---:|\n";
  } else {
    md << "\n- trajectory rows: the ground truth's on every gap frame; weights: trajectory / trajectory_facing\n\n"
       << "| gap | windows | solution | L2P | L2Q | NPSS | skating (cm) | ground distance mean / max (cm) | "
          "facing mean / max (deg) | s / window |\n"
       << "|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|\n";
  }
  mf::bench::stream_gap_table(md.str(), args.gaps, [&](int T) {
    return paths ? run_paths(args, T, clips, bench.stats, bench.ctx) : run_gap(args, T, clips, bench.stats, bench.ctx);
  }, args.out);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return mf::bench::benchmark_main<Args>(
      argc, argv, "trajectory-bench",
      "The latent solver's trajectory energy on the validation clips (docs/CONSTRAINTS.md, \"Trajectory\").",
      add_options, run);
}
