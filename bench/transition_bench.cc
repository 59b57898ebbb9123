// transition-bench: transitions between two clips (tasks/transition/transition.h
// run_transition) on the held-out clips, per transition length N (docs/BENCHMARKS.md,
// "Transitions"):
//
// - One take: a window of C + N + C frames of one clip (canonicalised at
//   frame C - 1, as the protocol's windows), A its first C frames and B its
//   last C; the N frames between them are the ground truth. With
//   `--place keep` (B where it was) the transition is gap filling on the
//   window, so the table also checks that it equals run_fill's output
//   bit for bit; with `auto` B is placed from A's and B's own speeds, and the
//   table shows how far the placement puts B's first frame from the truth.
//   L2P over the N frames, as the protocol's gap filling.
// - Two takes: A the first C frames of a window of one clip, B the first C
//   frames of a window of another clip (pairs spread over the split), so no
//   ground truth: foot skating over the N frames (cm, as the protocol's) and
//   the root's continuity, the largest change of the root's ground velocity
//   from one frame step to the next over the seams (cm per frame per frame),
//   beside the same over the kept parts of A and B (the clips' own).
//   `keep` here is what a user gets from concatenating the two files by hand
//   and filling the gap.
//
//   transition-bench [--model FILE] [--split validation|train] [--max-windows N] [--threads N]
//                    [--lengths 10,20,30,60] [--context 30] [--methods interp,nemf-detail]
//                    [--source PATH] [--cache-dir DIR] [--out FILE]
#include <ATen/Parallel.h>

#include <chrono>
#include <cmath>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "bench/metrics.h"
#include "bench/options.h"
#include "bench/protocol.h"
#include "bench/text.h"
#include "prior/runtime/nemf_runtime.h"
#include "tasks/transition/transition.h"

namespace {

using mf::bench::fixed;

struct Args : mf::bench::ModelBenchOptions {
  std::vector<int> lengths{10, 20, 30, 60};
  int context = 30;
  std::vector<std::string> methods{"interp", "nemf-detail"};
  std::string out;
};

void add_options(CLI::App& app, Args& a) {
  mf::bench::add_model_bench_options(app, a);
  mf::bench::add_list_option(app, "--lengths", a.lengths, "transition lengths N (default 10,20,30,60)");
  app.add_option("--context", a.context, "frames kept of A and of B (default 30)")->check(CLI::Range(2, 1000));
  app.add_option("--methods", a.methods, "methods (default interp nemf-detail)");
  app.add_option("--out", a.out, "also write the markdown to FILE");
}

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

mf::TransitionRequest request(int frames, mf::TransitionRequest::Placement place) {
  mf::TransitionRequest r;
  r.frames = frames;
  r.place = place;
  return r;
}

// The root's ground position (x, z) at frame f, cm.
Eigen::Vector2d ground_cm(const mf::Motion& m, int f) {
  return Eigen::Vector2d(m.root_positions[f].x(), m.root_positions[f].z()) * 100.0;
}

// The facing angle (radians about +Y) of the root's `forward` axis at frame f.
double facing(const mf::Motion& m, int f, const Eigen::Vector3d& forward) {
  const Eigen::Vector3d v = m.rotation(f, 0) * forward;
  return std::atan2(v.x(), v.z());
}

// The largest change of the root's ground velocity between consecutive frame
// steps whose three frames lie in [first, last] (cm per frame per frame).
double largest_velocity_change(const mf::Motion& m, int first, int last) {
  double worst = 0.0;
  for (int f = first + 1; f + 1 <= last; ++f) {
    const Eigen::Vector2d a = ground_cm(m, f) - ground_cm(m, f - 1), b = ground_cm(m, f + 1) - ground_cm(m, f);
    worst = std::max(worst, (b - a).norm());
  }
  return worst;
}

struct OneTakeRow {
  mf::bench::MetricAccumulator metrics;
  double placement_cm = 0.0, placement_deg = 0.0, fill_difference = 0.0, seconds = 0.0;
  int windows = 0;
};

// The one-take rows of one length: every method with `keep`, and with `auto`.
std::string one_take(const Args& args, int N, const std::vector<mf::Clip>& clips, const mf::bench::EvalStats& stats,
                     const mf::TaskContext& ctx, std::vector<double>* interp_l2p) {
  const int C = args.context, length = 2 * C + N;
  const std::vector<mf::Window> windows =
      mf::bench::cap_windows(mf::bench::protocol_windows(clips, length, 40), args.split.max_windows);
  std::vector<int> evaluated, known;
  for (int f = 0; f < length; ++f) (f >= C && f < C + N ? evaluated : known).push_back(f);
  const Eigen::Vector3d forward = ctx.model->rig().root_forward;
  std::ostringstream rows;
  for (const std::string& method : args.methods) {
    for (auto place : {mf::TransitionRequest::Placement::kKeep, mf::TransitionRequest::Placement::kAuto}) {
      OneTakeRow row{mf::bench::MetricAccumulator(stats)};
      for (const mf::Window& w : windows) {
        const mf::Motion truth = mf::bench::canonicalise(clips[w.clip].motion.slice(w.start, w.start + length), C - 1);
        const mf::Motion a = truth.slice(0, C), b = truth.slice(C + N, length);
        const Clock::time_point t0 = Clock::now();
        const mf::TransitionResult r = mf::run_transition(a, b, request(N, place), method, 0, ctx);
        row.seconds += seconds_since(t0);
        row.metrics.add(truth, r.motions[0], evaluated, known);
        ++row.windows;
        if (place == mf::TransitionRequest::Placement::kAuto) {
          const mf::Motion placed = mf::place_transition_clip(a, b, C - 1, 0, N);
          row.placement_cm += (ground_cm(placed, 0) - ground_cm(truth, C + N)).norm();
          double d = std::abs(facing(placed, 0, forward) - facing(truth, C + N, forward));
          row.placement_deg += std::min(d, 2 * M_PI - d) * 180.0 / M_PI;
        } else {
          const mf::Motion filled = mf::run_fill(mf::bench::hide_unknown_frames(truth, known), C, C + N, method, ctx);
          for (size_t i = 0; i < filled.rotations.size(); ++i)
            row.fill_difference = std::max(
                row.fill_difference, (filled.rotations[i].coeffs() - r.motions[0].rotations[i].coeffs()).cwiseAbs().maxCoeff());
          for (size_t i = 0; i < filled.root_positions.size(); ++i)
            row.fill_difference = std::max(
                row.fill_difference, (filled.root_positions[i] - r.motions[0].root_positions[i]).cwiseAbs().maxCoeff());
        }
      }
      if (row.windows == 0) return "| " + std::to_string(N) + " | 0 windows |\n";
      const double l2p = row.metrics.summary().l2p;
      const bool keep = place == mf::TransitionRequest::Placement::kKeep;
      if (method == "interp" && keep) interp_l2p->push_back(l2p);
      const double base = interp_l2p->empty() ? 0.0 : interp_l2p->back();
      rows << "| " << N << " | " << row.windows << " | " << method << " | " << (keep ? "keep" : "auto") << " | "
           << fixed(l2p, 3) << " | " << (base > 0 ? fixed(l2p / base, 3) : "-") << " | "
           << (keep ? "= fill: max difference " + fixed(row.fill_difference, 6)
                    : fixed(row.placement_cm / row.windows, 1) + " cm, " + fixed(row.placement_deg / row.windows, 1) +
                          " deg")
           << " | " << fixed(row.seconds / row.windows, 3) << " |\n";
    }
  }
  return rows.str();
}

// The two-take rows of one length: A from one clip, B from another.
std::string two_takes(const Args& args, int N, const std::vector<mf::Clip>& clips, const mf::bench::EvalStats& stats,
                      const mf::TaskContext& ctx) {
  const int C = args.context;
  const std::vector<mf::Window> windows =
      mf::bench::cap_windows(mf::bench::protocol_windows(clips, C, 97), args.split.max_windows);
  const int W = static_cast<int>(windows.size());
  std::vector<int> generated;
  for (int f = C; f < C + N; ++f) generated.push_back(f);
  std::ostringstream rows;
  for (const std::string& method : args.methods) {
    for (auto place : {mf::TransitionRequest::Placement::kKeep, mf::TransitionRequest::Placement::kAuto}) {
      mf::bench::SkatingTerms skating;
      double seam = 0.0, own = 0.0, seconds = 0.0;
      int pairs = 0;
      for (int i = 0; i < W; ++i) {
        // B: the first window half the list away that comes from another clip.
        int k = (i + W / 2) % W;
        while (k != i && windows[k].clip == windows[i].clip) k = (k + 1) % W;
        if (k == i) continue;
        const mf::Window &wa = windows[i], &wb = windows[k];
        const mf::Motion a = mf::bench::canonicalise(clips[wa.clip].motion.slice(wa.start, wa.start + C), C - 1);
        const mf::Motion b = clips[wb.clip].motion.slice(wb.start, wb.start + C);
        const Clock::time_point t0 = Clock::now();
        const mf::TransitionResult r = mf::run_transition(a, b, request(N, place), method, 0, ctx);
        seconds += seconds_since(t0);
        const mf::Motion& out = r.motions[0];
        const mf::bench::SkatingTerms s =
            mf::bench::foot_skating(mf::forward_kinematics(out), generated, stats.feet, stats.standing_height);
        skating.sum_cm += s.sum_cm;
        skating.count += s.count;
        seam += std::max(largest_velocity_change(out, C - 2, C + 1), largest_velocity_change(out, C + N - 2, C + N + 1));
        own += std::max(largest_velocity_change(out, 0, C - 1), largest_velocity_change(out, C + N, 2 * C + N - 1));
        ++pairs;
      }
      if (pairs == 0) return "| " + std::to_string(N) + " | 0 pairs |\n";
      rows << "| " << N << " | " << pairs << " | " << method << " | "
           << (place == mf::TransitionRequest::Placement::kKeep ? "keep (files concatenated)" : "auto") << " | "
           << fixed(skating.value(), 3) << " | " << fixed(seam / pairs, 2) << " | " << fixed(own / pairs, 2) << " | "
           << fixed(seconds / pairs, 3) << " |\n";
    }
  }
  return rows.str();
}

int run(Args& args, const std::string& command) {
  const mf::bench::BenchContext bench = mf::bench::load_bench_context(args);
  const std::vector<mf::Clip>& clips = args.split.clips(bench.data);

  std::ostringstream head;
  head << "## transition-bench\n\n- command: `" << command << "`\n- model: " << bench.model_path << "\n- "
       << args.split.split << " split, " << args.context << " frames kept of A and of B, torch threads: "
       << at::get_num_threads() << "\n\n### One take (ground truth between A and B)\n\n"
       << "| N | windows | method | placement | L2P | ratio to interp (keep) | check / placement error | s per "
          "transition |\n|---:|---:|---|---|---:|---:|---|---:|\n";
  std::vector<double> interp_l2p;
  mf::bench::stream_gap_table(
      head.str(), args.lengths, [&](int N) { return one_take(args, N, clips, bench.stats, bench.ctx, &interp_l2p); },
      args.out);
  std::ostringstream head2;
  head2 << "\n### Two takes (A and B from different clips)\n\n"
        << "| N | pairs | method | placement | foot skating (cm) | root velocity change at the seams (cm/frame^2) | "
           "the same within A and B | s per transition |\n|---:|---:|---|---|---:|---:|---:|---:|\n";
  mf::bench::stream_gap_table(
      head2.str(), args.lengths, [&](int N) { return two_takes(args, N, clips, bench.stats, bench.ctx); },
      args.out.empty() ? "" : args.out + ".two-takes.md");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return mf::bench::benchmark_main<Args>(
      argc, argv, "transition-bench",
      "Transitions between two clips on the held-out clips (docs/BENCHMARKS.md, \"Transitions\").", add_options,
      run);
}
