// alternatives-bench: several distinct solutions of one request
// (tasks/methods/jobs.h run_constrained with alternatives) on the gap-filling windows
// of the benchmark protocol (bench/protocol.h: 10 context frames, a gap of T,
// the target frame), optionally with end-effector targets (both hands at the
// gap's middle frame) and a contact pin (where a foot of the ground truth stays
// within 2 cm) inside the gap, taken from the ground truth. Per gap length it reports the
// quality (L2P, L2Q, NPSS, foot skating) of the method's solution, of the mean
// alternative, of the best alternative per window and of the worst alternative
// (the alternative index with the highest mean L2P), the diversity (mean
// pairwise joint position distance over the gap's frames between all the
// solutions of a window, cm) and the largest constraint error of any solution
// (docs/BENCHMARKS.md, "Alternatives"). With --features EXTRACTOR, NeMF's FID
// and diversity (bench/motion_features.h) of the method's solutions and of
// all alternatives against the real windows, and the features' mean pairwise
// distance between the alternatives of one request.
//
//   alternatives-bench [--model FILE] [--split validation|train] [--max-windows N] [--threads N]
//                      [--gaps 15,30] [--alternatives 4] [--method nemf-detail] [--seed 0]
//                      [--with-targets] [--features FILE] [--source PATH] [--cache-dir DIR] [--out FILE]
#include <ATen/Parallel.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bench/metrics.h"
#include "bench/motion_features.h"
#include "bench/options.h"
#include "bench/protocol.h"
#include "bench/text.h"
#include "tasks/methods/jobs.h"

namespace {

using mf::bench::fixed;

struct Args : mf::bench::ModelBenchOptions {
  std::vector<int> gaps{15, 30};
  int alternatives = 4;
  std::string method = "nemf-detail";
  uint64_t seed = 0;
  bool with_targets = false;
  std::string features;
  std::string out;
};

void add_options(CLI::App& app, Args& a) {
  mf::bench::add_model_bench_options(app, a);
  mf::bench::add_list_option(app, "--gaps", a.gaps, "gap lengths (default 15,30)");
  app.add_option("--alternatives", a.alternatives, "alternatives per request (default 4)")
      ->check(CLI::Range(1, mf::kMaxAlternatives));
  app.add_option("--method", a.method, "the method (default nemf-detail)");
  app.add_option("--seed", a.seed, "the requests' seed (default 0)");
  app.add_flag("--with-targets", a.with_targets,
               "add end-effector targets (both hands at the gap's middle frame) and a contact pin (the longest "
               "run of gap frames where a foot stays within 2 cm in the ground truth) from the ground truth");
  app.add_option("--features", a.features,
                 "the motion feature extractor (docs/BENCHMARKS.md, \"Distribution metrics\"): adds NeMF's FID and "
                 "diversity of the solutions and of the alternatives");
  app.add_option("--out", a.out, "also write the markdown to FILE");
}

// The features of one request's windows, when an extractor is given.
struct FeatureLog {
  const mf::bench::MotionFeatures* extractor = nullptr;
  mf::bench::FeatureSets sets;
  double within_request = 0.0;  // sum over requests of the alternatives' mean pairwise feature distance
  int requests = 0;

  void add(int T, const mf::Motion& truth, const std::vector<mf::Motion>& solutions) {
    if (!extractor) return;
    const std::string gap = "gap " + std::to_string(T);
    const Eigen::VectorXd real = extractor->features(truth);
    sets.add(gap + " / method's solution", real, extractor->features(solutions[0]));
    std::vector<Eigen::VectorXd> alternatives;
    for (size_t i = 1; i < solutions.size(); ++i) {
      alternatives.push_back(extractor->features(solutions[i]));
      sets.add(gap + " / alternatives", real, alternatives.back());
    }
    double sum = 0.0;
    int pairs = 0;
    for (size_t x = 0; x < alternatives.size(); ++x)
      for (size_t y = x + 1; y < alternatives.size(); ++y, ++pairs) sum += (alternatives[x] - alternatives[y]).norm();
    if (pairs) within_request += sum / pairs, ++requests;
  }
};

struct ContactPinChoice {
  int joint = -1, first = 0, last = 0;
};

// Targets and a pin inside the gap [a, b), from the ground truth `truth`.
void add_truth_targets(const mf::Motion& truth, int a, int b, mf::MotionConstraints* c) {
  const mf::GlobalPose pose = mf::forward_kinematics(truth);
  const int mid = (a + b) / 2;
  for (const char* hand : {"Hand_L", "Hand_R"}) {
    const int j = truth.skeleton.find(hand);
    if (j >= 0) c->effectors.push_back({mid, j, pose.position(mid, j), 1.0});
  }
  // The pin: the longest run of gap frames over which a foot stays within 2 cm
  // of where the run starts in the ground truth (a planted foot), 3 frames or more.
  ContactPinChoice best;
  for (const char* name : {"Foot_L", "Foot_R"}) {
    const int j = truth.skeleton.find(name);
    if (j < 0) continue;
    for (int s = a; s < b; ++s) {
      int e = s;
      while (e + 1 < b && (pose.position(e + 1, j) - pose.position(s, j)).norm() < 0.02) ++e;
      if (e - s > best.last - best.first) best = {j, s, e};
    }
  }
  if (best.joint >= 0 && best.last - best.first >= 2) c->contacts.push_back({best.joint, best.first, best.last});
}

// Mean pairwise distance (cm) of the joints over `frames` between the solutions.
double diversity_cm(const std::vector<mf::Motion>& solutions, const std::vector<int>& frames) {
  std::vector<mf::GlobalPose> poses;
  for (const mf::Motion& m : solutions) poses.push_back(mf::forward_kinematics(m));
  double sum = 0.0;
  long n = 0;
  for (size_t x = 0; x < poses.size(); ++x)
    for (size_t y = x + 1; y < poses.size(); ++y)
      for (int f : frames)
        for (int j = 0; j < solutions[x].num_joints(); ++j, ++n)
          sum += (poses[x].position(f, j) - poses[y].position(f, j)).norm() * 100.0;
  return n ? sum / n : 0.0;
}

std::string metric_cells(const mf::bench::MetricSummary& m) {
  return fixed(m.l2p, 3) + " | " + fixed(m.l2q, 3) + " | " + fixed(m.npss, 4) + " | " + fixed(m.skating_cm, 3);
}

// One gap length: the table rows.
std::string run_gap(const Args& args, int T, const std::vector<mf::Clip>& clips, const mf::bench::EvalStats& stats,
                    const mf::TaskContext& ctx, FeatureLog* features) {
  const int context = 10, length = context + T + 1, a = context, b = context + T;
  const std::vector<mf::Window> windows =
      mf::bench::cap_windows(mf::bench::protocol_windows(clips, length, 40), args.split.max_windows);
  std::vector<int> evaluated, known;
  for (int f = 0; f < length; ++f) (f >= a && f < b ? evaluated : known).push_back(f);
  const int N = args.alternatives;
  mf::bench::MetricAccumulator base(stats), mean_alt(stats), best(stats);
  std::vector<mf::bench::MetricAccumulator> per_alt(N, mf::bench::MetricAccumulator(stats));
  double diversity = 0.0, key_deg = 0.0, key_cm = 0.0, target_cm = 0.0, slide_cm = 0.0, seconds = 0.0;
  int within = 0, alts = 0;
  for (const mf::Window& w : windows) {
    const mf::Motion truth =
        mf::bench::canonicalise(clips[w.clip].motion.slice(w.start, w.start + length), context - 1);
    mf::MotionConstraints c = mf::MotionConstraints::full_pose(known);
    if (args.with_targets) add_truth_targets(truth, a, b, &c);
    const mf::Motion input = mf::bench::hide_unknown_frames(truth, known);
    const auto t0 = std::chrono::steady_clock::now();
    const mf::ConstrainedResult r = mf::run_constrained(input, c, args.method, N, ctx);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    base.add(truth, r.motions[0], evaluated, known);
    features->add(T, truth, r.motions);
    mf::bench::MetricAccumulator one_base(stats);
    one_base.add(truth, r.motions[0], evaluated, known);
    const double l2p0 = one_base.summary().l2p;
    double best_l2p = 1e30;
    size_t best_i = 1;
    for (int i = 1; i <= N; ++i) {
      mean_alt.add(truth, r.motions[i], evaluated, known);
      per_alt[i - 1].add(truth, r.motions[i], evaluated, known);
      mf::bench::MetricAccumulator one(stats);
      one.add(truth, r.motions[i], evaluated, known);
      const double l2p = one.summary().l2p;
      if (l2p < best_l2p) best_l2p = l2p, best_i = static_cast<size_t>(i);
      within += l2p <= 1.1 * l2p0;
      ++alts;
    }
    best.add(truth, r.motions[best_i], evaluated, known);
    diversity += diversity_cm(r.motions, evaluated);
    for (const mf::ConstraintReport& rep : r.reports) {
      key_deg = std::max(key_deg, rep.keys.rotation_max_deg);
      key_cm = std::max(key_cm, rep.keys.root_max_cm);
      target_cm = std::max(target_cm, rep.targets.max_cm);
      slide_cm = std::max(slide_cm, rep.contacts.max_cm);
    }
  }
  const int W = static_cast<int>(windows.size());
  if (W == 0) return "| " + std::to_string(T) + " | 0 windows |\n";
  size_t worst = 0;
  for (int i = 1; i < N; ++i)
    if (per_alt[i].summary().l2p > per_alt[worst].summary().l2p) worst = static_cast<size_t>(i);
  std::ostringstream row;
  const std::string lead = "| " + std::to_string(T) + " | " + std::to_string(W) + " | ";
  row << lead << "method's solution | " << metric_cells(base.summary()) << " | | | \n";
  row << lead << "mean alternative | " << metric_cells(mean_alt.summary()) << " | " << fixed(diversity / W, 2) << " | "
      << within << " / " << alts << " | \n";
  row << lead << "best alternative per window | " << metric_cells(best.summary()) << " | | | \n";
  row << lead << "worst alternative (#" << worst + 1 << ") | " << metric_cells(per_alt[worst].summary()) << " | | | "
      << "keys " << fixed(key_deg, 4) << " deg / " << fixed(key_cm, 4) << " cm; targets " << fixed(target_cm, 3)
      << " cm; pin slide " << fixed(slide_cm, 3) << " cm; " << fixed(seconds / W, 2) << " s / window |\n";
  return row.str();
}

int run(Args& args, const std::string& command) {
  mf::bench::BenchContext bench = mf::bench::load_bench_context(args);
  bench.ctx.seed = args.seed;
  const std::vector<mf::Clip>& clips = args.split.clips(bench.data);

  std::ostringstream md;
  md << "## alternatives-bench\n\n- command: `" << command << "`\n- model: " << bench.model_path << "\n- method: "
     << args.method << ", " << args.alternatives << " alternatives, seed " << args.seed
     << (args.with_targets ? ", with targets (both hands at the gap's middle) and a foot pin where the ground truth's foot is planted" : "")
     << "\n- " << args.split.split << " split, torch threads: " << at::get_num_threads() << "\n\n"
     << "| gap | windows | solution | L2P | L2Q | NPSS | skating (cm) | diversity (cm) | alternatives within 10 % "
        "of the method's L2P | constraints (largest error of any solution), time |\n"
     << "|---:|---:|---|---:|---:|---:|---:|---:|---:|---|\n";
  std::unique_ptr<mf::bench::MotionFeatures> extractor;
  FeatureLog features;
  if (!args.features.empty()) {
    extractor = std::make_unique<mf::bench::MotionFeatures>(args.features);
    features.extractor = extractor.get();
  }
  mf::bench::stream_gap_table(
      md.str(), args.gaps, [&](int T) { return run_gap(args, T, clips, bench.stats, bench.ctx, &features); },
      args.out);
  if (extractor) {
    std::ostringstream f;
    f << "\nNeMF's FID and diversity (features of " << args.features << "):\n\n"
      << features.sets.table() << "\nMean feature distance between two alternatives of one request: "
      << fixed(features.requests ? features.within_request / features.requests : 0.0, 3) << " (" << features.requests
      << " requests)\n";
    std::cout << f.str();
    if (!args.out.empty()) std::ofstream(args.out, std::ios::app) << f.str();
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return mf::bench::benchmark_main<Args>(
      argc, argv, "alternatives-bench",
      "Alternative solutions of gap filling on the validation clips (docs/BENCHMARKS.md, \"Alternatives\").",
      add_options, run);
}
