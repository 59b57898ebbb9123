// renav-bench: re-navigation (tasks/renav/renav.h) on validation clips along NeMF's
// test paths: a straight line (0 -> 4 m), circles of radius 0.5 m and 1.5 m
// (one full turn) and a sinusoid (4 m forward, amplitude 0.5 m, wavelength 2 m).
// Each path is a polyline walked at the reference clip's mean ground speed
// times --pace (default 1; polyline_frame_count / resample_polyline), so its
// frame count depends on the clip; the output's style and skating are compared
// with the reference played at the path's pace (played_at_speed) over as many
// frames. Prints a markdown table (docs/BENCHMARKS.md, "Re-navigation") and writes
// a few results as BVH files, their path CSVs and SVG top views.
//
//   renav-bench [--model FILE] [--source PATH] [--cache-dir DIR] [--threads N] [--clips N] [--paths straight,circle0.5,circle1.5,sine]
//               [--methods turned,nemf,nemf-adam] [--iterations N] [--adam-iterations N] [--ftol X]
//               [--w-path X] [--w-joints X] [--w-heading X] [--w-skate X] [--w-continuity X]
//               [--inits turned,reference,random] [--write N] [--out-dir DIR] [--out FILE]
//               [--profile N] [--verbose 1]
//
// --profile N prints the cost of one energy evaluation (and its parts) with
// gradient on a 128-frame window on libtorch (tasks/reference/renav_energy.h),
// median of N; --verbose 1 prints every window's terms before and after the
// solve.
//
// Reference clips: validation clips whose mean ground speed over their first
// (up to) 600 frames lies in [0.7, 2.5] m/s (walking and running) and that are
// long enough to cover every requested path at that speed (so the output of
// N frames is compared with the reference's first N frames, time-aligned),
// spread evenly; the reference is those first (up to) 600 frames.
// Methods: "turned" is the non-learned baseline (each reference frame's root
// turned to the path's tangent and placed on the path; no prior), "nemf" and
// "nemf-adam" the solvers.
// Metrics: path error (cm, mean over frames of the horizontal distance between
// the output's root and the target), foot skating (cm, bench/metrics.h, NeMF's
// definition with the model rig's standing heights), soft-DTW divergence
// (gamma 0.1) of the heading-frame joint positions and of the heading-vs-tangent
// signal between the output and the reference over the same number of frames,
// wall time and iterations per clip.
#include <ATen/ATen.h>
#include <ATen/Parallel.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bench/metrics.h"
#include "bench/options.h"
#include "bench/text.h"
#include "prior/data/dataset.h"
#include "prior/model/model_file.h"
#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/motion/interpolation.h"
#include "prior/motion/motion_bvh.h"
#include "prior/runtime/nemf_runtime.h"
#include "prior/util/command_line.h"
#include "prior/util/threads.h"
#include "tasks/reference/renav_energy.h"
#include "tasks/reference/soft_dtw.h"
#include "tasks/renav/renav.h"

namespace {

using mf::bench::fixed;
using mf::bench::ms_since;

using Clock = std::chrono::steady_clock;
constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxReference = 600;  // frames of a clip used as the reference

struct Args {
  std::string model;
  mf::bench::DataSource data;
  int threads = 1;
  int clips = 6;
  double pace = 1.0;
  std::vector<std::string> paths{"straight", "circle0.5", "circle1.5", "sine"};
  std::vector<std::string> methods{"turned", "nemf", "nemf-adam"};
  std::map<std::string, double> numbers;
  std::vector<std::string> inits;
  int write = 2;
  int profile = 0;
  int verbose = 0;
  std::string out_dir = "out/renav";
  std::string out;
};

void add_options(CLI::App& app, Args& a) {
  app.add_option("--model", a.model, "the prior (default: the default model, see mf::default_model_path())");
  mf::bench::add_data_options(app, a.data);
  mf::bench::add_threads_option(app, a.threads);
  app.add_option("--clips", a.clips, "reference clips (validation clips walking or running)")
      ->check(mf::cli::at_least(1));
  app.add_option("--pace", a.pace,
                 "walk each path at this multiple of the reference's mean ground speed (style and skating are "
                 "compared with the reference played at that pace)")
      ->check(CLI::Range(0.25, 4.0));
  mf::bench::add_list_option(app, "--paths", a.paths, "straight, circle<R> (radius R in metres), sine");
  mf::bench::add_list_option(app, "--methods", a.methods, "turned (the baseline), nemf, nemf-adam")
      ->check(CLI::IsMember({"turned", "nemf", "nemf-adam"}));
  mf::bench::add_list_option(app, "--inits", a.inits,
                             "the solver's starts, among turned, reference, random (default: the solver's)");
  app.add_option("--write", a.write, "write BVH results, path CSVs and SVG top views of the first N clips");
  app.add_option("--profile", a.profile, "print the cost of one energy evaluation, median of N (0: no)");
  app.add_option("--verbose", a.verbose, "1: print every window's terms before and after the solve");
  app.add_option("--out-dir", a.out_dir, "folder of the written results");
  app.add_option("--out", a.out, "also write the markdown to FILE");
  mf::bench::add_number_options(app, a.numbers,
                                {{"iterations", "L-BFGS iteration cap per window (0: the default)"},
                                 {"adam-iterations", "Adam iteration cap per window (0: the default)"},
                                 {"ftol", "relative function tolerance"},
                                 {"overlap", "frames shared by consecutive windows"}},
                                "Solver settings (default: tasks/renav/renav.h)");
  mf::bench::add_number_options(app, a.numbers,
                                {{"w-path", "weight of the root path"},
                                 {"w-joints", "weight of the soft-DTW divergence of the joints"},
                                 {"w-heading", "weight of the soft-DTW divergence of the heading"},
                                 {"w-skate", "weight of foot skating"},
                                 {"w-continuity", "weight of the continuity with the previous window"},
                                 {"lock-ramp", "foot locking ramp in frames (negative: no foot locking)"},
                                 {"match-pace", "1: play the reference at the path's pace (the default), 0: as it is"}},
                                "Energy weights and output (default: tasks/renav/renav.h)");
}

mf::RenavOptions options_for(const Args& a, const std::string& method) {
  std::map<std::string, double> n = a.numbers;
  mf::RenavOptions o =
      mf::default_renav_options(method == "nemf-adam" ? mf::LatentOptimizer::Adam : mf::LatentOptimizer::Lbfgs);
  auto take = [&](const char* key, auto* field) { mf::bench::take_number(n, key, field); };
  if (method == "nemf") {
    take("iterations", &o.max_iterations);
    n.erase("adam-iterations");
  } else {
    take("adam-iterations", &o.max_iterations);
    n.erase("iterations");
  }
  take("ftol", &o.function_tolerance);
  take("w-path", &o.weights.path);
  take("w-joints", &o.weights.joints);
  take("w-heading", &o.weights.heading);
  take("w-skate", &o.weights.foot_skating);
  take("w-continuity", &o.weights.continuity);
  take("overlap", &o.overlap);
  take("lock-ramp", &o.foot_lock_ramp);
  take("match-pace", &o.match_pace);
  if (!n.empty()) throw mf::InputError("unknown option --" + n.begin()->first);
  o.inits = a.inits;
  return o;
}

// A test path as a polyline in a local frame: starts at the origin heading +Z.
std::vector<Eigen::Vector2d> test_polyline(const std::string& name) {
  std::vector<Eigen::Vector2d> v;
  if (name == "straight") return {{0.0, 0.0}, {0.0, 4.0}};
  if (name.rfind("circle", 0) == 0) {
    const double r = std::atof(name.c_str() + 6);
    if (!(r > 0)) throw mf::InputError("bad circle radius in '" + name + "'");
    for (int i = 0; i <= 360; ++i) {
      const double t = 2.0 * kPi * i / 360;
      v.emplace_back(r - r * std::cos(t), r * std::sin(t));
    }
    return v;
  }
  if (name == "sine") {
    for (int i = 0; i <= 400; ++i) {
      const double z = 4.0 * i / 400;
      v.emplace_back(0.5 * std::sin(2.0 * kPi * z / 2.0), z);
    }
    return v;
  }
  throw mf::InputError("unknown path '" + name + "' (straight, circle<R>, sine)");
}

// The non-learned baseline: reference frame f (time-stretched when the path is
// longer than the reference) with its root turned to the target's tangent by
// the angle between the target's and the reference's travel directions, and
// placed on the path at the reference's height.
mf::Motion turned_baseline(const mf::Motion& ref, const std::vector<Eigen::Vector2d>& path, const Eigen::Vector3d& fwd) {
  const int N = static_cast<int>(path.size()), R = ref.num_frames();
  std::vector<Eigen::Vector2d> ref_xz(R);
  std::vector<double> heading(R);
  for (int f = 0; f < R; ++f) {
    ref_xz[f] = {ref.root_positions[f].x(), ref.root_positions[f].z()};
    const Eigen::Vector3d h = ref.rotation(f, 0).normalized() * fwd;
    heading[f] = std::atan2(h.x(), h.z());
  }
  const std::vector<double> ref_travel = mf::tangent_yaws(ref_xz, heading);
  const std::vector<double> target = mf::tangent_yaws(path);
  mf::Motion out = mf::Motion::identity(ref.skeleton, N, ref.fps);
  for (int f = 0; f < N; ++f) {
    const int g = N <= R ? f : static_cast<int>(std::lround(static_cast<double>(f) * (R - 1) / (N - 1)));
    for (int j = 0; j < ref.num_joints(); ++j) out.rotation(f, j) = ref.rotation(g, j);
    const double delta = target[f] - ref_travel[g];
    out.rotation(f, 0) =
        (Eigen::Quaterniond(Eigen::AngleAxisd(delta, Eigen::Vector3d::UnitY())) * ref.rotation(g, 0).normalized())
            .normalized();
    out.root_positions[f] = {path[f].x(), ref.root_positions[g].y(), path[f].y()};
  }
  return out;
}

struct Metrics {
  double path_cm = 0, skate_cm = 0, ref_skate_cm = 0, dtw_joints = 0, dtw_heading = 0, ms = 0, iterations = 0;
  double energy0 = 0, energy1 = 0;
  int windows = 0;
  std::map<std::string, int> inits;
};

// Heading-frame joints [1, T, J*3] and the heading-vs-tangent signal [1, T, 1]
// of a motion (tangent: `tangent_of`'s root path, or the motion's own).
void signals(const mf::Motion& m, const mf::RigInfo& rig, const std::vector<double>& tangent, at::Tensor* joints,
             at::Tensor* heading) {
  const int T = m.num_frames();
  const mf::WindowTensors t = mf::window_tensors(m, 0, T, rig, 0);
  *joints = mf::heading_relative_positions(t.local_rotations, rig).flatten(-2);
  *heading = at::empty({1, T, 1}, at::kFloat);
  for (int f = 0; f < T; ++f) {
    const Eigen::Vector3d h = m.rotation(f, 0).normalized() * rig.root_forward;
    heading->data_ptr<float>()[f] = static_cast<float>(std::cos(std::atan2(h.x(), h.z()) - tangent[f]));
  }
}

std::vector<double> root_tangents(const mf::Motion& m, const Eigen::Vector3d& fwd) {
  std::vector<Eigen::Vector2d> xz;
  std::vector<double> heading;
  for (int f = 0; f < m.num_frames(); ++f) {
    xz.emplace_back(m.root_positions[f].x(), m.root_positions[f].z());
    const Eigen::Vector3d h = m.rotation(f, 0).normalized() * fwd;
    heading.push_back(std::atan2(h.x(), h.z()));
  }
  return mf::tangent_yaws(xz, heading);
}

double skating_cm(const mf::Motion& m, const std::vector<mf::bench::FootJoint>& feet, const std::vector<double>& standing) {
  std::vector<int> frames;
  for (int f = 1; f < m.num_frames(); ++f) frames.push_back(f);
  return mf::bench::foot_skating(mf::forward_kinematics(m), frames, feet, standing).value();
}

void write_svg(const std::string& file, const std::string& title, const std::vector<Eigen::Vector2d>& target,
               const std::vector<std::pair<std::string, mf::Motion>>& results) {
  const char* colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd"};
  double x0 = 1e9, x1 = -1e9, z0 = 1e9, z1 = -1e9;
  auto grow = [&](double x, double z) {
    x0 = std::min(x0, x), x1 = std::max(x1, x), z0 = std::min(z0, z), z1 = std::max(z1, z);
  };
  for (const auto& p : target) grow(p.x(), p.y());
  for (const auto& r : results)
    for (const auto& p : r.second.root_positions) grow(p.x(), p.z());
  const double size = 480, margin = 30;
  const double span = std::max({x1 - x0, z1 - z0, 0.5});
  const double scale = (size - 2 * margin) / span;
  auto X = [&](double x) { return margin + (x - x0) * scale; };
  auto Y = [&](double z) { return size - margin - (z - z0) * scale; };  // +Z up
  std::ofstream s(file);
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << size << "\" height=\"" << size + 40
    << "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s << "<text x=\"8\" y=\"16\">" << title << " (top view, x right, z up; 1 m = " << fixed(scale, 0) << " px)</text>\n";
  auto polyline = [&](const std::vector<Eigen::Vector2d>& pts, const char* colour, const char* extra) {
    s << "<polyline fill=\"none\" stroke=\"" << colour << "\" stroke-width=\"2\" " << extra << " points=\"";
    for (const auto& p : pts) s << fixed(X(p.x()), 1) << "," << fixed(Y(p.y()), 1) << " ";
    s << "\"/>\n";
  };
  polyline(target, "#888888", "stroke-dasharray=\"6,4\"");
  s << "<text x=\"8\" y=\"" << size + 14 << "\" fill=\"#888888\">target path (dashed)</text>\n";
  for (size_t i = 0; i < results.size(); ++i) {
    std::vector<Eigen::Vector2d> pts;
    for (const auto& p : results[i].second.root_positions) pts.emplace_back(p.x(), p.z());
    polyline(pts, colours[i % 4], "");
    s << "<text x=\"" << 160 + 110 * i << "\" y=\"" << size + 14 << "\" fill=\"" << colours[i % 4] << "\">"
      << results[i].first << " root</text>\n";
  }
  s << "<circle cx=\"" << fixed(X(target[0].x()), 1) << "\" cy=\"" << fixed(Y(target[0].y()), 1)
    << "\" r=\"4\" fill=\"black\"/>\n</svg>\n";
}

// Median wall time (ms) of `fn` over n runs after one warm-up.
template <class Fn>
double median_ms(int n, Fn&& fn) {
  fn();
  std::vector<double> t;
  for (int i = 0; i < n; ++i) {
    const auto t0 = Clock::now();
    fn();
    t.push_back(ms_since(t0));
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// The cost of one energy evaluation with gradient on a 128-frame window, and of its parts.
std::string profile(const mf::NemfModel& model, const mf::runtime::NemfRuntime& rt, const mf::Motion& ref, int n) {
  const int T = model.config().window;
  std::vector<Eigen::Vector2d> path;
  for (int f = 0; f < T; ++f) path.emplace_back(0.0, 0.04 * f);
  const mf::RenavWindow w = mf::make_renav_window(rt, ref, 0, T, path, 0, T);
  const int zl = model.config().zl, zg = model.config().zg;
  at::Tensor z_l = at::zeros({1, zl}).requires_grad_(true), z_g = at::zeros({1, zg}).requires_grad_(true);
  const at::Tensor frames = at::arange(T, at::kFloat);
  const mf::RigInfo& rig = model.rig();
  auto backward = [&](const at::Tensor& e) {
    e.backward();
    z_l.mutable_grad().reset();
    z_g.mutable_grad().reset();
  };
  std::ostringstream s;
  s << "| part (128 frames, forward + backward to z) | ms |\n|---|---:|\n";
  s << "| decoder | " << fixed(median_ms(n, [&] { backward(model.decode(frames, z_l, z_g).sum()); }), 2) << " |\n";
  s << "| decoder + GMP + root integration | " << fixed(median_ms(n, [&] {
         at::Tensor r = model.decode(frames, z_l, z_g);
         mf::GmpOutput g = model.predict_global(r, mf::GmpUse::Steering);
         backward(model.root_positions(r, g).sum());
       }), 2) << " |\n";
  s << "| decoder + heading-frame joints (FK) | " << fixed(median_ms(n, [&] {
         at::Tensor r = model.decode(frames, z_l, z_g);
         backward(mf::heading_relative_positions(r, rig).sum());
       }), 2) << " |\n";
  for (const char* term : {"path", "joints", "heading"}) {
    mf::RenavWeights wt;
    wt.path = std::string(term) == "path" ? 1.0 : 0.0;
    wt.joints = std::string(term) == "joints" ? 0.5 : 0.0;
    wt.heading = std::string(term) == "heading" ? 1.0 : 0.0;
    s << "| full energy, only the " << term << " term | "
      << fixed(median_ms(n, [&] { backward(mf::evaluate_renav_energy(model, w, wt, z_l, z_g).total); }), 2) << " |\n";
  }
  s << "| full energy (default weights) | "
    << fixed(median_ms(n, [&] { backward(mf::evaluate_renav_energy(model, w, {}, z_l, z_g).total); }), 2) << " |\n";
  return s.str();
}

int run(Args& args, const std::string& command) {
  if (args.model.empty()) args.model = mf::default_model_path();
  if (args.model.empty()) throw mf::InputError("no default model: pass --model FILE");
  for (const std::string& p : args.paths) test_polyline(p);  // fails early on an unknown path
  mf::set_compute_threads(args.threads);

  mf::TaskContext ctx;
  ctx.model = std::make_shared<const mf::runtime::NemfRuntime>(mf::runtime::NemfRuntime::load(args.model));
  const mf::runtime::NemfRuntime& model = *ctx.model;
  const mf::RigInfo& rig = model.rig();
  const double fps = model.config().fps;
  const mf::Dataset data = mf::bench::load_data(args.data, false);

  // Foot joints and standing heights for the skating metric, from the model's rig.
  std::vector<mf::bench::FootJoint> feet = mf::bench::metric_foot_joints(rig.skeleton);
  std::vector<double> standing;
  for (const auto& fj : feet) {
    double h = 0.0;
    for (int k = 0; k < rig.num_feet(); ++k) {
      if (rig.foot_joints[k] == fj.joint) h = rig.foot_heights[k];
    }
    standing.push_back(h);
  }

  // Reference clips.
  std::vector<mf::Motion> refs;
  std::vector<std::string> ref_names;
  {
    std::vector<int> eligible;
    for (size_t c = 0; c < data.validation.size(); ++c) {
      const mf::Motion& m = data.validation[c].motion;
      if (m.num_frames() < 128 || std::abs(m.fps - fps) > 1e-3) continue;
      const mf::Motion ref = m.slice(0, std::min(kMaxReference, m.num_frames()));
      const double v = mf::mean_ground_speed(ref);
      if (v < 0.7 || v > 2.5) continue;
      int longest = 0;
      for (const std::string& p : args.paths) longest = std::max(longest, mf::polyline_frame_count(test_polyline(p), v, fps));
      if (longest <= ref.num_frames()) eligible.push_back(static_cast<int>(c));
    }
    const int n = std::min<int>(args.clips, static_cast<int>(eligible.size()));
    for (int i = 0; i < n; ++i) {
      const int c = eligible[static_cast<size_t>(i) * eligible.size() / n];
      const mf::Motion& m = data.validation[c].motion;
      refs.push_back(m.slice(0, std::min(kMaxReference, m.num_frames())));
      ref_names.push_back(data.validation[c].name);
    }
    std::cerr << eligible.size() << " eligible validation clips, using " << refs.size() << "\n";
  }

  std::ostringstream md;
  auto emit = [&](const std::string& text) {
    std::cout << text << std::flush;
    md << text;
  };
  emit("## renav-bench\n\n- command: `" + command + "`\n- model: " + args.model + " (" + model.config().describe() +
       ")\n- torch threads: " + std::to_string(at::get_num_threads()) + "\n- reference clips: " +
       std::to_string(refs.size()) + " validation clips (");
  for (size_t i = 0; i < ref_names.size(); ++i) emit((i ? ", " : "") + ref_names[i]);
  emit(")\n- path speed: " + fixed(args.pace, 2) + " x the reference's mean ground speed\n");
  for (const std::string& m : args.methods) {
    if (m == "turned") continue;
    const mf::RenavOptions o = options_for(args, m);
    const mf::RenavWeights& w = o.weights;
    emit("- `" + m + "`: " + (o.optimizer == mf::LatentOptimizer::Adam ? "Adam" : "L-BFGS") + ", max iterations " +
         (o.max_iterations ? std::to_string(o.max_iterations) : std::string("default")) + ", ftol " +
         fixed(o.function_tolerance, 6) + "; weights path " + fixed(w.path, 2) + ", joints " + fixed(w.joints, 2) +
         ", heading " + fixed(w.heading, 2) + ", foot skating " + fixed(w.foot_skating, 2) + ", continuity " +
         fixed(w.continuity, 2) + "; match pace " + (o.match_pace ? "yes" : "no") + "\n");
  }
  if (args.profile > 0 && !refs.empty()) {
    mf::NemfModel torch_model = mf::load_nemf(args.model);  // the energy's libtorch reference, for --profile
    torch_model.set_requires_grad(false);
    emit("\n" + profile(torch_model, model, refs[0], args.profile));
  }
  emit("\n| path | method | clips | frames | path error (cm) | foot skating (cm) | skating, reference (cm) | "
       "sDTW joints | sDTW heading | E0 -> E | iterations | s / clip | init (turned/reference/random) |\n"
       "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");


  std::filesystem::create_directories(args.out_dir);
  for (const std::string& path_name : args.paths) {
    const std::vector<Eigen::Vector2d> poly = test_polyline(path_name);
    std::vector<std::vector<std::pair<std::string, mf::Motion>>> written(refs.size());
    std::vector<std::vector<Eigen::Vector2d>> targets(refs.size());
    for (const std::string& method : args.methods) {
      Metrics sum;
      double frames_sum = 0;
      for (size_t c = 0; c < refs.size(); ++c) {
        const mf::Motion& ref = refs[c];
        const int N = mf::polyline_frame_count(poly, args.pace * mf::mean_ground_speed(ref), fps);
        const std::vector<Eigen::Vector2d> path = mf::resample_polyline(poly, N);
        targets[c] = path;
        frames_sum += N;
        mf::Motion out;
        const auto t0 = Clock::now();
        if (method == "turned") {
          out = turned_baseline(ref, path, rig.root_forward);
        } else {
          mf::RenavReport report;
          out = mf::renavigate(model, ref, path, fps, options_for(args, method), ctx, &report);
          sum.iterations += report.iterations;
          for (const auto& w : report.windows) {
            if (args.verbose) {
              std::cerr << "  window " << w.begin << "+" << w.length << " init " << w.init << ":";
              for (size_t t = 0; t < w.final_terms.size(); ++t)
                std::cerr << " " << w.final_terms[t].first << " " << fixed(w.initial_terms[t].second, 3) << "->"
                          << fixed(w.final_terms[t].second, 3);
              std::cerr << ", " << w.iterations << " it, " << w.message << "\n";
            }
            sum.energy0 += w.initial_energy;
            sum.energy1 += w.final_energy;
            sum.inits[w.init] += 1;
            ++sum.windows;
          }
        }
        sum.ms += ms_since(t0);
        double err = 0;
        for (int f = 0; f < N; ++f)
          err += std::hypot(out.root_positions[f].x() - path[f].x(), out.root_positions[f].z() - path[f].y());
        sum.path_cm += err / N * 100.0;
        sum.skate_cm += skating_cm(out, feet, standing);
        const mf::Motion paced = args.pace == 1.0 ? ref : mf::played_at_speed(ref, args.pace);
        const mf::Motion ref_same = paced.slice(0, std::min(N, paced.num_frames()));
        sum.ref_skate_cm += skating_cm(ref_same, feet, standing);
        double dj = 0, dh = 0;
        {
          at::NoGradGuard no_grad;
          at::Tensor oj, oh, rj, rh;
          signals(out, rig, mf::tangent_yaws(path), &oj, &oh);
          signals(ref_same, rig, root_tangents(ref_same, rig.root_forward), &rj, &rh);
          dj = mf::soft_dtw_divergence(oj, rj, mf::kNemfSoftDtwGamma).item<double>();
          dh = mf::soft_dtw_divergence(oh, rh, mf::kNemfSoftDtwGamma).item<double>();
        }
        sum.dtw_joints += dj;
        sum.dtw_heading += dh;
        if (static_cast<int>(c) < args.write) {
          written[c].emplace_back(method, out);
          std::string stem = ref_names[c].substr(0, ref_names[c].rfind('.'));
          const std::string base = args.out_dir + "/" + stem + "_" + path_name + "_" + method;
          mf::write_motion(base + ".bvh", out, mf::default_bvh_layout(out.skeleton));
        }
        std::cerr << path_name << " " << method << " clip " << c << ": N " << N << ", " << fixed(ms_since(t0), 0)
                  << " ms, path " << fixed(err / N * 100.0, 1) << " cm, sDTW joints " << fixed(dj, 2) << ", heading "
                  << fixed(dh, 2) << "\n";
      }
      const double n = std::max<size_t>(1, refs.size());
      std::string init = "-";
      if (sum.windows > 0) {
        init = std::to_string(sum.inits["turned"]) + "/" + std::to_string(sum.inits["reference"]) + "/" +
               std::to_string(sum.inits["random"]);
      }
      emit("| " + path_name + " | " + method + " | " + std::to_string(refs.size()) + " | " + fixed(frames_sum / n, 0) +
           " | " + fixed(sum.path_cm / n, 1) + " | " + fixed(sum.skate_cm / n, 3) + " | " +
           fixed(sum.ref_skate_cm / n, 3) + " | " + fixed(sum.dtw_joints / n, 2) + " | " + fixed(sum.dtw_heading / n, 2) +
           " | " + (sum.windows ? fixed(sum.energy0 / n, 2) + " -> " + fixed(sum.energy1 / n, 2) : std::string("-")) +
           " | " + (sum.windows ? fixed(sum.iterations / n, 1) : std::string("-")) + " | " +
           fixed(sum.ms / n / 1000.0, 2) + " | " + init + " |\n");
    }
    for (size_t c = 0; c < refs.size() && static_cast<int>(c) < args.write; ++c) {
      std::string stem = ref_names[c].substr(0, ref_names[c].rfind('.'));
      const std::string base = args.out_dir + "/" + stem + "_" + path_name;
      write_svg(base + ".svg", stem + ", " + path_name, targets[c], written[c]);
      std::ofstream csv(base + ".csv");
      csv << "x,z\n";
      for (const auto& p : targets[c]) csv << fixed(p.x(), 5) << "," << fixed(p.y(), 5) << "\n";
    }
  }
  emit("\nBVH results, path CSVs and SVG top views of the first " + std::to_string(args.write) + " clips: " +
       args.out_dir + "/\n");
  if (!args.out.empty()) std::ofstream(args.out) << md.str();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return mf::bench::benchmark_main<Args>(
      argc, argv, "renav-bench",
      "Re-navigation (tasks/renav/renav.h) of validation clips along NeMF's test paths (docs/BENCHMARKS.md, "
      "\"Re-navigation\"); details at the top of bench/renav_bench.cc.",
      add_options, run);
}
