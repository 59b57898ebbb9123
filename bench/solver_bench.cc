// solver-bench: quality and speed of the latent solvers (tasks/latent/latent_solver.h)
// against interpolation, on the windows of the benchmark protocol
// (bench/protocol.h: gap filling 10 + T + 1 frames, sparse keyframes in
// 128-frame windows), with every solver setting on the command line so that
// weights and tolerances can be tuned on training clips (--split train) and
// reported on validation clips. Prints markdown tables (docs/BENCHMARKS.md,
// "Latent solvers").
//
//   solver-bench --model FILE [--split validation|train] [--threads N] [--max-windows N]
//                [--source PATH] [--cache-dir DIR]
//                [--tasks gap,sparse,caps,effector,partial,long,none] [--methods interp,nemf,nemf-adam]
//                [--lengths 5,15] [--spacings 5,10] [--caps 5,10,20,40] [--speed N] [--op-profile] [--out FILE]
//                [--iterations N] [--ftol X] [--ptol X] [--rank N] [--eigen-scaling 0|1]
//                [--keyed-iterations N] [--adam-iterations N] [--adam-tol X] [--lock-ramp N] [--effector-falloff N] [--overwrite 0|1]
//                [--penalty squared|absolute] [--init NAME] [--twostage FILE] [--citl FILE]
//                [--w-rot X] [--w-pos X] [--w-root-rot X] [--w-root X] [--w-prior X] [--w-skate X]
//                [--w-smooth X] [--w-effector X] [--libtorch-energy]
//
// Tasks: gap and sparse as in the protocol; effector and partial add targets
// (hands, feet) or partial keys (root only, legs only) at frames 15, 45, 75,
// 105 of 128-frame windows with full keys every 30 frames; long solves
// 300-frame clips (several overlapping windows) and compares the acceleration
// at the window joins with elsewhere; caps solves every gap length and every
// spacing once per L-BFGS iteration cap in --caps (one table per length or
// spacing and method: how many iterations each start needs for a quality);
// none runs only --speed.
// --speed N adds the speed table: N sparse windows (a key every 15th frame),
// each solved by every solver method; wall time, iterations, evaluations, the
// time in the optimiser (the rest is the initialiser, the decode and the
// overwrite) and the floor (one decoder forward + backward over 128 frames,
// times the iterations; the Eigen runtime's, libtorch's with --libtorch-energy)
// per solve. --op-profile adds, after each gap or sparse table and
// after the speed table, the operators run per energy evaluation and the time in
// them (bench/op_profile.h; with --threads 1). L-BFGS minimises the Eigen
// runtime's energy where it ports the window's terms, as the product does
// (tasks/latent/latent_solver.h); --libtorch-energy has them minimise the
// libtorch energy (tasks/reference/libtorch_energies.h), for comparison.
//
// Transformers (tasks/methods/transformer_methods.h): --twostage/--citl FILE, else
// motionfield-twostage.mfm / motionfield-citl.mfm next to --model when they
// exist. With them, --methods also takes "context", "detail", "citl" (one
// pass of the transformer; no solver; speed = inference time per window) and
// "nemf-context", "nemf-detail", "nemf-citl" (L-BFGS, with the L-BFGS options
// above, started from that transformer's initialiser), and --init takes
// "context-encoder", "detail-encoder", "citl-encoder".
#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bench/metrics.h"
#include "bench/op_profile.h"
#include "bench/options.h"
#include "bench/text.h"
#include "bench/protocol.h"
#include "prior/data/dataset.h"
#include "prior/inbetween/inbetweener.h"
#include "prior/model/model_file.h"
#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "prior/runtime/inbetween_runtime.h"
#include "prior/runtime/nemf_runtime.h"
#include "prior/util/command_line.h"
#include "prior/util/threads.h"
#include "tasks/constraints/interpolation_fill.h"
#include "tasks/latent/initializers.h"
#include "tasks/latent/latent_solver.h"
#include "tasks/methods/transformer_methods.h"
#include "tasks/reference/libtorch_energies.h"

namespace {

using mf::bench::fixed;
using mf::bench::ms_since;

using Clock = std::chrono::steady_clock;

// CPU time of every thread of the process: less disturbed than wall time by
// other jobs on the machine.
double process_cpu_ms() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

struct Args {
  std::string model;
  mf::bench::SplitChoice split;
  mf::bench::DataSource data;
  int threads = 1;
  std::vector<std::string> tasks{"gap", "sparse"};
  std::vector<std::string> methods{"interp", "nemf", "nemf-adam"};
  std::vector<int> lengths{5, 15, 30, 45, 90};
  std::vector<int> spacings{5, 10, 15, 20, 30};
  std::vector<int> caps{5, 10, 20, 40};  // task "caps": L-BFGS iteration caps
  int speed = 0;
  bool op_profile = false;
  std::string out;
  std::map<std::string, double> numbers;  // solver overrides
  std::string penalty;
  std::string init;
  mf::bench::TransformerFiles transformer_files;  // default: next to --model
  mf::TaskContext transformers;  // the loaded transformers (filled by run())
  bool libtorch_energy = false;  // the latent solvers minimise the libtorch energy (TaskContext::reference)
  mf::TaskContext prior;  // the prior (and with libtorch_energy the reference energies), as the solvers' context (run())
};

// A stage of an in-betweener ("context", "detail", "citl"): one transformer
// pass, no solver.
bool is_transformer_method(const std::string& method) { return mf::find_inbetweener_stage(method) != nullptr; }

// The initialiser of "nemf-<stage>" ("nemf-detail": "detail-encoder"); "" for
// the other methods.
std::string transformer_initializer(const std::string& method) {
  const std::string prefix = "nemf-";
  if (method.rfind(prefix, 0) != 0 || !is_transformer_method(method.substr(prefix.size()))) return "";
  return method.substr(prefix.size()) + "-encoder";
}

void add_options(CLI::App& app, Args& a) {
  app.add_option("--model", a.model, "the prior")->required();
  mf::bench::add_split_options(app, a.split);
  mf::bench::add_data_options(app, a.data);
  mf::bench::add_threads_option(app, a.threads);
  mf::bench::add_list_option(app, "--tasks", a.tasks, "gap, sparse, caps, effector, partial, long, none")
      ->check(CLI::IsMember({"gap", "sparse", "caps", "effector", "partial", "long", "none"}));
  mf::bench::add_list_option(app, "--methods", a.methods,
                             "interp, nemf, nemf-adam; with the transformers context, detail, citl, nemf-context, "
                             "nemf-detail, nemf-citl");
  mf::bench::add_list_option(app, "--lengths", a.lengths, "gap lengths T of the gap and caps tasks");
  mf::bench::add_list_option(app, "--spacings", a.spacings, "key spacings k of the sparse and caps tasks");
  mf::bench::add_list_option(app, "--caps", a.caps, "L-BFGS iteration caps of the caps task");
  app.add_option("--speed", a.speed, "add the speed table over N sparse windows (0: none)")
      ->check(mf::cli::at_least(0));
  app.add_flag("--op-profile", a.op_profile,
               "count the operators of each gap and sparse row and of each method's --speed solves (bench/op_profile.h; "
               "slows them; use --threads 1)");
  app.add_flag("--libtorch-energy", a.libtorch_energy,
               "the latent solvers minimise the libtorch energy (tasks/reference/energies.h) instead of the Eigen "
               "runtime's (tasks/latent/runtime_energy.h), to compare them");
  app.add_option("--out", a.out, "also write the markdown to FILE");
  app.add_option("--penalty", a.penalty, "squared or absolute (default: the solver's, squared)")
      ->check(CLI::IsMember({"squared", "absolute"}));
  app.add_option("--init", a.init,
                 "the solver's initialiser (tasks/latent/initializers.h; with the transformers also context-encoder, "
                 "detail-encoder, citl-encoder)");
  mf::bench::add_transformer_options(app, a.transformer_files);
  mf::bench::add_number_options(app, a.numbers,
                                {{"iterations", "L-BFGS iteration cap per window (0: the solver's default)"},
                                 {"ftol", "L-BFGS relative function tolerance"},
                                 {"ptol", "L-BFGS relative parameter tolerance"},
                                 {"rank", "L-BFGS memory (rank of the Hessian approximation)"},
                                 {"eigen-scaling", "1: Ceres' approximate eigenvalue scaling of L-BFGS, 0: off"},
                                 {"keyed-iterations", "L-BFGS iterations on the key-frame terms first (0: none)"},
                                 {"adam-iterations", "Adam iteration cap per window"},
                                 {"adam-tol", "Adam's convergence tolerance (relative improvement)"}},
                                "Solver settings (default: tasks/latent/latent_solver.h)");
  mf::bench::add_number_options(app, a.numbers,
                                {{"overwrite", "1: overwrite the known values in the output, 0: the raw solution"},
                                 {"lock-ramp", "foot-locking ramp in frames (negative: off)"},
                                 {"effector-falloff", "end-effector IK falloff in frames (negative: off)"},
                                 {"w-rot", "weight of the key rotations"},
                                 {"w-pos", "weight of the key positions"},
                                 {"w-root-rot", "weight of the key root orientations"},
                                 {"w-root", "weight of the key root translations"},
                                 {"w-prior", "weight of the latent prior"},
                                 {"w-skate", "weight of foot skating"},
                                 {"w-smooth", "weight of smoothness"},
                                 {"w-effector", "weight of the end-effector targets"}},
                                "Output and energy weights (default: tasks/latent/latent_solver.h, tasks/reference/energies.h)");
}

mf::LatentSolverOptions solver_options(const Args& a, const std::string& method) {
  mf::LatentSolverOptions o =
      mf::default_solver_options(method == "nemf-adam" ? mf::LatentOptimizer::Adam : mf::LatentOptimizer::Lbfgs);
  std::map<std::string, double> n = a.numbers;
  auto take = [&](const char* key, auto* field) { mf::bench::take_number(n, key, field); };
  if (method == "nemf" || !transformer_initializer(method).empty()) {
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
  take("overwrite", &o.overwrite_known);
  take("lock-ramp", &o.foot_lock_ramp);
  take("effector-falloff", &o.effector_falloff);
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
  if (!transformer_initializer(method).empty()) {
    o.initializer = mf::make_initializer(transformer_initializer(method), a.transformers);
  } else if (!a.init.empty()) {
    o.initializer = mf::make_initializer(a.init, a.transformers);
  }
  return o;
}

std::string describe(const mf::LatentSolverOptions& o) {
  std::ostringstream s;
  const mf::EnergyWeights& w = o.weights;
  s << (o.optimizer == mf::LatentOptimizer::Adam ? "Adam" : "L-BFGS") << ", max iterations "
    << (o.max_iterations ? std::to_string(o.max_iterations) : std::string("default"));
  if (o.optimizer == mf::LatentOptimizer::Lbfgs)
    s << ", ftol " << o.function_tolerance << ", rank " << o.lbfgs_rank << ", keys-only stage "
      << (o.keyed_iterations >= 0 ? std::to_string(o.keyed_iterations) : std::string("default"));
  s << "; weights: rotation " << w.rotation << ", position " << w.position << ", root orientation "
    << w.root_orientation << ", root translation " << w.root_translation << ", latent prior " << w.latent_prior
    << ", foot skating " << w.foot_skating << ", smoothness " << w.smoothness << "; penalty "
    << (w.penalty == mf::Penalty::Squared ? "squared" : "absolute");
  return s.str();
}

// A solver method (complete_motion with solver_options) or a transformer pass
// (inbetweener_fill; `report` stays empty).
mf::Motion complete(const mf::runtime::NemfRuntime& model, const Args& args, const std::string& method,
                    const mf::Motion& input, const mf::MotionConstraints& constraints, mf::CompletionReport* report) {
  int stage = 0;
  if (const mf::InbetweenerKind* kind = mf::find_inbetweener_stage(method, &stage)) {
    const mf::runtime::InbetweenerRuntime& t =
        mf::require_inbetweener(args.transformers, kind->name, "method '" + method + "'");
    return mf::inbetweener_fill(t, stage, input, constraints, mf::LongGapPolicy::Throw);
  }
  return mf::complete_motion(model, input, constraints, solver_options(args, method), args.prior, report);
}

struct Row {
  int parameter = 0;
  mf::bench::MetricSummary metrics;
  double ms = 0.0, iterations = 0.0, evaluations = 0.0, raw_rot_deg = 0.0, raw_root_cm = 0.0, energy_ratio = 0.0;
};

// One method on one protocol row.
struct Runner {
  const mf::runtime::NemfRuntime& model;
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
    mf::Motion out = complete(model, args, method, input, mf::MotionConstraints::full_pose(known), &report);
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

std::vector<int> joints_named(const mf::Skeleton& s, const std::vector<std::string>& parts) {
  std::vector<int> out;
  for (int j = 0; j < s.num_joints(); ++j) {
    for (const std::string& p : parts) {
      if (s.names[j].find(p) != std::string::npos) {
        out.push_back(j);
        break;
      }
    }
  }
  return out;
}

// End-effector and partial constraints on 128-frame windows with full keys
// every 30 frames: the same windows solved with and without the extra
// constraints at the midpoints 15, 45, 75, 105.
std::string constraint_table(const std::string& task, const std::string& method, const Runner& runner,
                             const std::vector<mf::Clip>& clips, const mf::bench::EvalStats& stats, const Args& args,
                             const Eigen::Vector3d& forward) {
  const int length = 128;
  const auto windows = mf::bench::cap_windows(mf::bench::protocol_windows(clips, length, 40), args.split.max_windows);
  const std::vector<int> keys = mf::bench::sparse_keyframes(length, 30);
  const std::vector<int> mids = {15, 45, 75, 105};
  const mf::Skeleton& skel = runner.model.rig().skeleton;
  struct Variant {
    std::string name;
    std::vector<int> joints;  // partial: constrained joints; effector: target joints
    bool root_position = false;
  };
  std::vector<Variant> variants;
  if (task == "effector") {
    variants.push_back({"none (keys every 30 only)", {}, false});
    variants.push_back({"hands", joints_named(skel, {"Hand"}), false});
    variants.push_back({"hands and feet", joints_named(skel, {"Hand", "Foot"}), false});
  } else {
    variants.push_back({"none (keys every 30 only)", {}, false});
    variants.push_back({"root only (rotation and position)", {0}, true});
    variants.push_back({"legs only (local rotations)", joints_named(skel, {"Leg", "Foot", "Toe"}), false});
  }
  std::ostringstream s;
  s << "#### " << (task == "effector" ? "End-effector targets" : "Partial keys")
    << " at frames 15, 45, 75, 105 (128-frame windows, full keys every 30 frames), `" << method << "`\n\n"
    << "| constraint | windows | L2P | L2Q | NPSS | skating (cm) | skating GT (cm) | constrained error, raw: max / mean"
    << " | constrained error, output: max / mean | ms / window |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Variant& v : variants) {
    mf::bench::MetricAccumulator acc(stats);
    double raw_max = 0, raw_sum = 0, out_max = 0, out_sum = 0, ms = 0;
    long count = 0;
    for (const mf::Window& w : windows) {
      const mf::Motion truth = mf::bench::canonicalise(clips[w.clip].motion.slice(w.start, w.start + length), 0, forward);
      const mf::GlobalPose tp = mf::forward_kinematics(truth);
      mf::MotionConstraints c = mf::MotionConstraints::full_pose(keys);
      std::vector<int> shown = keys;
      if (!v.joints.empty()) {
        for (int f : mids) {
          if (task == "effector") {
            for (int j : v.joints) c.effectors.push_back({f, j, tp.position(f, j), 1.0});
          } else {
            c.keys.push_back({f, v.joints, v.root_position});
            shown.push_back(f);
          }
        }
        std::sort(c.keys.begin(), c.keys.end(), [](const mf::PoseKey& a, const mf::PoseKey& b) { return a.frame < b.frame; });
        std::sort(shown.begin(), shown.end());
      }
      const mf::Motion input = mf::bench::hide_unknown_frames(truth, shown);
      std::vector<int> evaluated;
      for (int f = 0; f < length; ++f) {
        if (!std::binary_search(keys.begin(), keys.end(), f)) evaluated.push_back(f);
      }
      mf::CompletionReport report;
      const auto t0 = Clock::now();
      const mf::Motion out = complete(runner.model, args, method, input, c, &report);
      ms += ms_since(t0);
      acc.add(truth, out, evaluated, keys);
      if (v.joints.empty()) continue;
      if (task == "effector") {
        raw_max = std::max(raw_max, report.raw_effectors.max_cm);
        raw_sum += report.raw_effectors.mean_cm * report.raw_effectors.count;
        out_max = std::max(out_max, report.effectors.max_cm);
        out_sum += report.effectors.mean_cm * report.effectors.count;
        count += report.effectors.count;
      } else {
        raw_max = std::max(raw_max, report.raw_known.rotation_max_deg);
        raw_sum += report.raw_known.rotation_mean_deg * report.raw_known.rotations;
        count += report.raw_known.rotations;
        for (int f : mids) {
          for (int j : v.joints) {
            const double d = mf::geodesic_angle(out.rotation(f, j), truth.rotation(f, j)) * 180.0 / M_PI;
            out_max = std::max(out_max, d);
            out_sum += d;
          }
          if (v.root_position) {
            const double cm = (out.root_positions[f] - truth.root_positions[f]).norm() * 100.0;
            out_max = std::max(out_max, cm);
          }
        }
      }
    }
    const mf::bench::MetricSummary m = acc.summary();
    const char* unit = task == "effector" ? " cm" : " deg";
    const long mid_count = static_cast<long>(windows.size() * mids.size() * v.joints.size());
    s << "| " << v.name << " | " << m.windows << " | " << fixed(m.l2p, 3) << " | " << fixed(m.l2q, 3) << " | "
      << fixed(m.npss, 4) << " | " << fixed(m.skating_cm, 3) << " | " << fixed(m.truth_skating_cm, 3) << " | ";
    if (v.joints.empty()) {
      s << "- | - | ";
    } else {
      s << fixed(raw_max, 2) << " / " << fixed(count ? raw_sum / count : 0.0, 2) << unit << " | " << fixed(out_max, 2)
        << " / " << fixed(task == "effector" ? (count ? out_sum / count : 0.0) : (mid_count ? out_sum / mid_count : 0.0), 2)
        << unit << " | ";
    }
    s << fixed(ms / std::max<size_t>(1, windows.size()), 0) << " |\n";
    std::cerr << task << " " << v.name << " done\n";
  }
  if (task == "partial")
    s << "\nRaw error: every constrained local rotation (all keys) before the overwrite; output error: the "
         "constrained rotations (deg) and root positions (cm) at the partial keys after it.\n";
  return s.str();
}

// Mean acceleration (cm / frame^2) of the global joint positions at frames f
// (second difference around f), over the frames where `select` is true.
double mean_acceleration(const mf::GlobalPose& p, const std::vector<char>& select) {
  double sum = 0;
  long n = 0;
  for (int f = 1; f + 1 < p.frames; ++f) {
    if (!select[f]) continue;
    for (int j = 0; j < p.joints; ++j) {
      sum += (p.position(f + 1, j) - 2 * p.position(f, j) + p.position(f - 1, j)).norm() * 100.0;
      ++n;
    }
  }
  return n ? sum / n : 0.0;
}

// Clips longer than a window: 300-frame windows, keys every 20 frames; the
// acceleration near window joins (the cross-fades) against elsewhere.
std::string long_table(const std::string& method, const Runner& runner, const std::vector<mf::Clip>& clips,
                       const mf::bench::EvalStats& stats, const Args& args, const Eigen::Vector3d& forward) {
  const int length = 300;
  const auto windows = mf::bench::cap_windows(mf::bench::protocol_windows(clips, length, length), args.split.max_windows);
  const std::vector<int> keys = mf::bench::sparse_keyframes(length, 20);
  std::vector<int> evaluated;
  for (int f = 0; f < length; ++f) {
    if (!std::binary_search(keys.begin(), keys.end(), f)) evaluated.push_back(f);
  }
  mf::bench::MetricAccumulator acc(stats), acc_interp(stats);
  double seam_out = 0, rest_out = 0, seam_truth = 0, rest_truth = 0, seam_interp = 0, rest_interp = 0, ms = 0;
  int solved_windows = 0;
  for (const mf::Window& w : windows) {
    const mf::Motion truth = mf::bench::canonicalise(clips[w.clip].motion.slice(w.start, w.start + length), 0, forward);
    const mf::Motion input = mf::bench::hide_unknown_frames(truth, keys);
    mf::CompletionReport report;
    const auto t0 = Clock::now();
    const mf::Motion out = complete(runner.model, args, method, input, mf::MotionConstraints::full_pose(keys), &report);
    ms += ms_since(t0);
    solved_windows += static_cast<int>(report.windows.size());
    const mf::Motion interp = mf::interpolate_motion(input, keys);
    acc.add(truth, out, evaluated, keys);
    acc_interp.add(truth, interp, evaluated, keys);
    // Frames where two windows are cross-faded, and 4 frames either side.
    std::vector<char> seam(length, 0), rest(length, 1);
    std::vector<int> starts = report.window_starts;
    std::sort(starts.begin(), starts.end());
    const int W = runner.model.config().window;
    for (size_t i = 1; i < starts.size(); ++i) {
      const int a = starts[i], b = std::min(length, starts[i - 1] + W);
      for (int f = std::max(0, a - 4); f < std::min(length, b + 4); ++f) {
        seam[f] = 1;
        rest[f] = 0;
      }
    }
    const mf::GlobalPose po = mf::forward_kinematics(out), pt = mf::forward_kinematics(truth),
                         pi = mf::forward_kinematics(interp);
    seam_out += mean_acceleration(po, seam);
    rest_out += mean_acceleration(po, rest);
    seam_truth += mean_acceleration(pt, seam);
    rest_truth += mean_acceleration(pt, rest);
    seam_interp += mean_acceleration(pi, seam);
    rest_interp += mean_acceleration(pi, rest);
  }
  const double n = std::max<size_t>(1, windows.size());
  const mf::bench::MetricSummary m = acc.summary(), mi = acc_interp.summary();
  std::ostringstream s;
  s << "#### Clips longer than a window: 300 frames, keys every 20 frames, `" << method << "`\n\n"
    << m.windows << " clips, " << fixed(solved_windows / n, 1) << " solver windows per clip, "
    << fixed(ms / n, 0) << " ms per clip. Acceleration: mean |second difference| of the global joint positions "
    << "(cm / frame^2), at the cross-fades (+-4 frames) and elsewhere.\n\n"
    << "| motion | L2P | L2Q | NPSS | skating (cm) | acceleration at joins | acceleration elsewhere |\n"
    << "|---|---:|---:|---:|---:|---:|---:|\n"
    << "| `" << method << "` | " << fixed(m.l2p, 3) << " | " << fixed(m.l2q, 3) << " | " << fixed(m.npss, 4) << " | "
    << fixed(m.skating_cm, 3) << " | " << fixed(seam_out / n, 3) << " | " << fixed(rest_out / n, 3) << " |\n"
    << "| `interp` | " << fixed(mi.l2p, 3) << " | " << fixed(mi.l2q, 3) << " | " << fixed(mi.npss, 4) << " | "
    << fixed(mi.skating_cm, 3) << " | " << fixed(seam_interp / n, 3) << " | " << fixed(rest_interp / n, 3) << " |\n"
    << "| ground truth | | | | " << fixed(m.truth_skating_cm, 3) << " | " << fixed(seam_truth / n, 3) << " | "
    << fixed(rest_truth / n, 3) << " |\n";
  std::cerr << "long " << method << " done\n";
  return s.str();
}

// Median wall time of one decoder forward + backward to the latents over the
// model's window (128 frames): the Eigen runtime's (forward + VJP), which the
// solve runs, and libtorch's (autograd), which --libtorch-energy runs.
double decoder_step_ms(const mf::runtime::NemfRuntime& model) {
  const mf::NemfConfig& c = model.config();
  const Eigen::VectorXd frames = Eigen::VectorXd::LinSpaced(c.window, 0.0, c.window - 1.0);
  const Eigen::VectorXf zl = Eigen::VectorXf::Zero(c.zl), zg = Eigen::VectorXf::Zero(c.zg);
  mf::runtime::DecoderWorkspace ws;
  mf::runtime::MatrixRXf out;
  Eigen::VectorXf g_zl, g_zg;
  std::vector<double> t;
  for (int i = 0; i < 21; ++i) {
    const auto t0 = Clock::now();
    model.decode(frames, zl, zg, &ws, &out);
    model.decode_vjp(&ws, mf::runtime::MatrixRXf::Ones(out.rows(), out.cols()), &g_zl, &g_zg);
    if (i > 0) t.push_back(ms_since(t0));
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

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

// One gap-filling row of the protocol (context frames, a gap of T, one
// target frame) for `method`.
Row gap_row(const Runner& runner, const std::string& method, const std::vector<mf::Clip>& clips,
            const mf::bench::EvalStats& stats, const Eigen::Vector3d& forward, int T) {
  const mf::bench::ProtocolOptions protocol;
  const int length = protocol.context + T + 1, a = protocol.context, b = protocol.context + T;
  const auto windows =
      mf::bench::cap_windows(mf::bench::protocol_windows(clips, length, protocol.stride), runner.args.split.max_windows);
  std::vector<int> evaluated, known;
  for (int f = 0; f < length; ++f) (f >= a && f < b ? evaluated : known).push_back(f);
  mf::bench::MetricAccumulator acc(stats);
  Row row;
  row.parameter = T;
  for (const mf::Window& w : windows) {
    const mf::Motion truth =
        mf::bench::canonicalise(clips[w.clip].motion.slice(w.start, w.start + length), protocol.context - 1, forward);
    const mf::Motion input = mf::bench::hide_unknown_frames(truth, known);
    acc.add(truth, runner.solve(method, input, known, &row), evaluated, known);
  }
  row.metrics = acc.summary();
  return row;
}

// One sparse-keyframe row (128-frame windows, a key every k frames).
Row sparse_row(const Runner& runner, const std::string& method, const std::vector<mf::Clip>& clips,
               const mf::bench::EvalStats& stats, const Eigen::Vector3d& forward, int k) {
  const mf::bench::ProtocolOptions protocol;
  const int length = protocol.sparse_window;
  const auto windows =
      mf::bench::cap_windows(mf::bench::protocol_windows(clips, length, protocol.stride), runner.args.split.max_windows);
  const std::vector<int> keys = mf::bench::sparse_keyframes(length, k);
  std::vector<int> evaluated;
  for (int f = 0; f < length; ++f) {
    if (!std::binary_search(keys.begin(), keys.end(), f)) evaluated.push_back(f);
  }
  mf::bench::MetricAccumulator acc(stats);
  Row row;
  row.parameter = k;
  for (const mf::Window& w : windows) {
    const mf::Motion truth = mf::bench::canonicalise(clips[w.clip].motion.slice(w.start, w.start + length), 0, forward);
    const mf::Motion input = mf::bench::hide_unknown_frames(truth, keys);
    acc.add(truth, runner.solve(method, input, keys, &row), evaluated, keys);
  }
  row.metrics = acc.summary();
  return row;
}

// --op-profile: one operator profile per gap or sparse row.
std::unique_ptr<mf::bench::OpProfile> row_profile(const Args& args) {
  return args.op_profile ? std::make_unique<mf::bench::OpProfile>() : nullptr;
}

std::string profile_table(const mf::bench::OpProfile& profile, const std::string& method, const std::string& what,
                          const Row& row) {
  return "#### Operators of `" + method + "`, " + what + " (" + fixed(row.evaluations, 0) +
         " evaluations; the profile's callback slows every operator)\n\n" + profile.table(row.evaluations, "evaluation") +
         "\n";
}

int run(Args& args, const std::string& command) {
  mf::set_compute_threads(args.threads);

  // The libtorch prior times its decoder (--speed) and, with --libtorch-energy,
  // gives the solvers its energies (TaskContext::reference).
  auto loaded = std::make_shared<mf::NemfModel>(mf::load_nemf(args.model));
  loaded->set_requires_grad(false);
  args.prior.model = std::make_shared<const mf::runtime::NemfRuntime>(mf::runtime::NemfRuntime::load(args.model));
  const mf::runtime::NemfRuntime& model = *args.prior.model;
  if (args.libtorch_energy) args.prior.reference = mf::libtorch_energies(loaded);
  mf::bench::load_transformers(args.transformer_files, args.model, &args.transformers, false);
  const mf::Dataset data = mf::bench::load_data(args.data, false);
  const mf::bench::EvalStats stats = mf::bench::compute_eval_stats(data.train);
  const std::vector<mf::Clip>& clips = args.split.clips(data);

  std::ostringstream md;
  auto emit = [&](const std::string& text) {
    std::cout << text << std::flush;
    md << text;
  };
  emit("## solver-bench\n\n- command: `" + command + "`\n- model: " + args.model + " (" + model.config().describe() +
       ")\n- split: " + args.split.split + " (" + std::to_string(clips.size()) + " clips)\n- torch threads: " +
       std::to_string(at::get_num_threads()) + "\n- BLAS: " + mf::describe_blas() + "\n");
  for (const mf::InbetweenerKind& kind : mf::inbetweener_kinds()) {
    const mf::runtime::InbetweenerRuntime* t = args.transformers.inbetweener(kind.name);
    emit("- " + kind.name + " transformer: " + (t ? t->describe() : std::string("not loaded")) + "\n");
  }
  for (const std::string& m : args.methods) {
    if (is_transformer_method(m)) emit("- `" + m + "`: one pass of the transformer (no solver)\n");
    else if (m != "interp") emit("- `" + m + "`: " + describe(solver_options(args, m)) + "\n");
  }
  emit("\n");

  const Runner runner{model, args};
  const Eigen::Vector3d forward = model.rig().root_forward;
  for (const std::string& task : args.tasks) {
    if (task == "none") continue;
    for (const std::string& method : args.methods) {
      std::vector<Row> rows;
      if (task == "gap") {
        std::string profiles;
        for (int T : args.lengths) {
          const auto profile = row_profile(args);
          rows.push_back(gap_row(runner, method, clips, stats, forward, T));
          if (profile) profiles += profile_table(*profile, method, "gap T = " + std::to_string(T), rows.back());
          std::cerr << "gap " << T << " " << method << " done\n";
        }
        emit(table("#### Gap filling, `" + method + "`", "T", rows) + "\n" + profiles);
      } else if (task == "sparse") {
        std::string profiles;
        for (int k : args.spacings) {
          const auto profile = row_profile(args);
          rows.push_back(sparse_row(runner, method, clips, stats, forward, k));
          if (profile) profiles += profile_table(*profile, method, "keys every " + std::to_string(k), rows.back());
          std::cerr << "sparse " << k << " " << method << " done\n";
        }
        emit(table("#### Sparse keyframes (128 frames), `" + method + "`", "k", rows) + "\n" + profiles);
      } else if (task == "caps") {
        if (method == "interp" || is_transformer_method(method) || method == "nemf-adam") continue;
        for (const bool gap : {true, false}) {
          for (int p : gap ? args.lengths : args.spacings) {
            std::vector<Row> cap_rows;
            for (int cap : args.caps) {
              Args capped = args;
              capped.numbers["iterations"] = cap;
              const Runner r{model, capped};
              cap_rows.push_back(gap ? gap_row(r, method, clips, stats, forward, p)
                                     : sparse_row(r, method, clips, stats, forward, p));
              cap_rows.back().parameter = cap;
              std::cerr << (gap ? "gap " : "sparse ") << p << " " << method << " cap " << cap << " done\n";
            }
            emit(table(std::string("#### Iteration cap, ") + (gap ? "gap T = " : "keys every k = ") +
                           std::to_string(p) + ", `" + method + "`",
                       "cap", cap_rows) +
                 "\n");
          }
        }
      } else if (task == "long") {
        if (method == "interp") continue;
        emit(long_table(method, runner, clips, stats, args, forward) + "\n");
      } else if (task == "effector" || task == "partial") {
        if (method == "interp") continue;
        emit(constraint_table(task, method, runner, clips, stats, args, forward) + "\n");
      } else {
        throw mf::InputError("unknown task " + task);
      }
    }
  }

  if (args.speed > 0) {
    const double step = args.libtorch_energy ? decoder_step_ms(*loaded) : decoder_step_ms(model);
    const auto windows = mf::bench::cap_windows(mf::bench::protocol_windows(clips, 128, 40), args.speed);
    const std::vector<int> keys = mf::bench::sparse_keyframes(128, 15);
    std::ostringstream s;
    s << "#### Speed: sparse keyframes every 15 frames, 128-frame windows, " << windows.size() << " windows, "
      << at::get_num_threads() << " torch thread(s)\n\n"
      << "Decoder forward + backward over 128 frames (" << (args.libtorch_energy ? "libtorch" : "the Eigen runtime")
      << "): " << fixed(step, 2) << " ms (median of 20).\n\n"
      << "| method | ms / solve (mean) | ms / solve (median) | process CPU ms / solve (mean) | iterations | "
         "evaluations | of which in the optimiser (ms, mean) | floor: decoder f+b x iterations (ms) | L2P |\n"
         "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    std::map<std::string, double> mean_ms;
    std::ostringstream profiles;
    for (const std::string& method : args.methods) {
      if (method == "interp") continue;
      std::vector<double> ms;
      double iters = 0, evals = 0, cpu = 0, optimiser = 0;
      mf::bench::MetricAccumulator acc(stats);
      std::vector<int> evaluated;
      for (int f = 0; f < 128; ++f) {
        if (!std::binary_search(keys.begin(), keys.end(), f)) evaluated.push_back(f);
      }
      std::unique_ptr<mf::bench::OpProfile> profile;
      if (args.op_profile) profile = std::make_unique<mf::bench::OpProfile>();
      for (const mf::Window& w : windows) {
        const mf::Motion truth = mf::bench::canonicalise(clips[w.clip].motion.slice(w.start, w.start + 128), 0, forward);
        const mf::Motion input = mf::bench::hide_unknown_frames(truth, keys);
        mf::CompletionReport report;
        const auto t0 = Clock::now();
        const double c0 = process_cpu_ms();
        mf::Motion out = complete(model, args, method, input, mf::MotionConstraints::full_pose(keys), &report);
        ms.push_back(ms_since(t0));
        cpu += process_cpu_ms() - c0;
        iters += report.iterations;
        for (const auto& r : report.windows) {
          evals += r.evaluations;
          optimiser += r.wall_ms;
        }
        acc.add(truth, out, evaluated, keys);
      }
      const double n = std::max<size_t>(1, ms.size());
      double sum = 0;
      for (double x : ms) sum += x;
      std::vector<double> sorted = ms;
      std::sort(sorted.begin(), sorted.end());
      mean_ms[method] = sum / n;
      s << "| " << method << " | " << fixed(sum / n, 0) << " | " << fixed(sorted.empty() ? 0 : sorted[sorted.size() / 2], 0)
        << " | " << fixed(cpu / n, 0) << " | " << fixed(iters / n, 1) << " | " << fixed(evals / n, 1) << " | " << fixed(optimiser / n, 0) << " | " << fixed(step * iters / n, 0) << " | "
        << fixed(acc.summary().l2p, 3) << " |\n";
      if (profile) {
        profiles << "\n#### Operators of `" << method << "` (" << fixed(evals / n, 1)
                 << " evaluations per solve; the profile's callback slows every operator)\n\n"
                 << profile->table(evals, "evaluation");
      }
    }
    s << profiles.str();
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
  return mf::bench::benchmark_main<Args>(
      argc, argv, "solver-bench",
      "Quality and speed of the latent solvers against interpolation on the benchmark protocol's windows "
      "(docs/BENCHMARKS.md, \"Latent solvers\"); the tasks are described at the top of bench/solver_bench.cc.",
      add_options, run);
}
