// motionfield-bench: the LaFAN1-style benchmark of docs/BENCHMARKS.md. Loads the
// data set, computes the evaluation statistics on the training split, loads the
// prior once (shared by every method that needs it), runs every (task, method)
// pair on the validation split and the prior's own evaluation (recon, fps,
// seams, sample), and prints markdown tables.
#include <ATen/Parallel.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bench/metrics.h"
#include "bench/options.h"
#include "bench/text.h"
#include "bench/prior_eval.h"
#include "bench/protocol.h"
#include "prior/data/dataset.h"
#include "prior/inbetween/inbetweener.h"
#include "prior/model/model_file.h"
#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/runtime/inbetween_runtime.h"
#include "prior/runtime/nemf_runtime.h"
#include "bench/foreign_data.h"
#include "bench/synthetic_rigs.h"
#include "prior/util/command_line.h"
#include "prior/util/threads.h"
#include "tasks/context/model_rig.h"
#include "tasks/methods/jobs.h"
#include "tasks/methods/transformer_methods.h"
#include "tasks/reference/libtorch_energies.h"

namespace {

using mf::bench::fixed;

const std::vector<std::string> kPriorTasks = {"recon", "fps", "seams", "sample"};

bool is_prior_task(const std::string& name) {
  for (const std::string& t : kPriorTasks) {
    if (t == name) return true;
  }
  return false;
}

struct Args {
  std::vector<std::string> methods;
  bool methods_given = false;
  std::vector<std::string> task_names;  // as given, split below into:
  std::vector<mf::bench::Task> tasks;
  std::vector<std::string> prior_tasks;
  bool tasks_given = false;
  std::string model;
  mf::bench::TransformerFiles transformers;
  bool no_model = false;
  int samples = 256;
  int seed = 1;
  int threads = 2;
  mf::bench::DataSource data;
  mf::bench::SplitChoice split;
  std::string rig = "native";
  std::string out;
  bool l2p_axes = false;
  bool print_stats = false;
  std::vector<int> gaps;    // gap lengths (default: the protocol's)
  std::vector<int> spacings;  // keyframe spacings of the sparse task (default: the protocol's)
  std::vector<int> resample_factors;  // resampling: every k-th frame kept (default: the protocol's)
  std::vector<std::string> resample_ratios;  // resampling: a:b rows
  bool trajectory = false;  // gap filling with the ground-truth trajectory
  bool l2t = false;
  std::string dataset = "bandai";  // or "foreign": real capture on other rigs (bench/foreign_data.h)
  std::string foreign_source = mf::default_foreign_archive();
  double foreign_fps = 0;  // the foreign clips captured at this rate only, at it (0: every clip at the model's rate)
  std::string windows_csv;  // per-window scores and signals (bench/window_log.h)
  bool no_fallback = false;  // the latent solvers keep their own result everywhere
  bool libtorch_energy = false;  // the latent solvers minimise the libtorch energy (TaskContext::reference)
  std::string features;  // the feature extractor of the distribution metrics (bench/motion_features.h)
};

void add_options(CLI::App& app, Args& args) {
  mf::bench::add_list_option(app, "--methods", args.methods, "methods to run (default: every available method)");
  mf::bench::add_list_option(app, "--tasks", args.task_names,
                             "gap, sparse, resample, and with a model recon, fps, seams, sample (default: gap, sparse, "
                             "resample, plus the prior's four when a model is loaded)");
  app.add_option("--model", args.model, "the prior (default: the default model, see mf::default_model_path())");
  app.add_flag("--no-model", args.no_model, "run without a prior (methods that need one are skipped)");
  mf::bench::add_transformer_options(app, args.transformers);
  app.add_option("--samples", args.samples, "windows drawn for the sample task")->check(mf::cli::at_least(1));
  app.add_option("--seed", args.seed, "seed of the sample task")->check(mf::cli::at_least(0));
  mf::bench::add_threads_option(app, args.threads);
  mf::bench::add_data_options(app, args.data);
  mf::bench::add_split_options(app, args.split);
  app.add_option("--rig", args.rig,
                 "gap and sparse tables on a synthetic rig (mixamo, cmu, lafan1, unreal, rigify, smpl, mixamo-rough; "
                 "bench/synthetic_rigs.h): each window rewritten onto it, solved there, brought back; needs "
                 "motionfield-rig.json next to the model")
      ->each([](const std::string& name) {
        if (name != "native") mf::bench::rig_variant(name);  // validates the name
      });
  app.add_option("--out", args.out, "also write the markdown to FILE");
  app.add_flag("--l2p-axes", args.l2p_axes, "add columns splitting L2P into horizontal (x, z) and vertical (y) parts");
  mf::bench::add_list_option(app, "--gaps", args.gaps, "gap lengths of the gap task (default: 5, 15, 30, 45, 90)");
  mf::bench::add_list_option(app, "--spacings", args.spacings,
                             "keyframe spacings of the sparse task (default: 5, 10, 15, 20, 30)");
  mf::bench::add_list_option(app, "--resample-factors", args.resample_factors,
                             "resampling: keep every k-th frame of a 65-frame window, bring it back to the full rate "
                             "(default: 2; 65 frames allow 2, 4, 8, 16, 32, 64)");
  app.add_option("--resample-ratios", args.resample_ratios,
                 "resampling rows a:b: every a-th frame of the window is the input, the result is scored at every "
                 "b-th (5:4 is a 1.25 upsampling like 24 -> 30 fps, 4:5 a downsampling like 30 -> 24); added to "
                 "--resample-factors")
      ->delimiter(',')
      ->each([](const std::string& r) { mf::bench::parse_resample_ratio(r); });  // validates
  app.add_flag("--trajectory", args.trajectory,
               "gap filling with the ground truth's trajectory of the gap (through the constrained path; methods "
               "without it are skipped)");
  app.add_flag("--l2t", args.l2t, "add the L2T column (trajectory error, bench/metrics.h)");
  app.add_option("--dataset", args.dataset,
                 "bandai: the training data's held-out clips (--source); foreign: real capture of other people on "
                 "other rigs (--foreign-source, bench/foreign_data.h), each window solved on its own rig as the CLI "
                 "gets it, scored on the model's rig, with tables per rig convention and content")
      ->check(CLI::IsMember({"bandai", "foreign"}));
  app.add_option("--foreign-source", args.foreign_source, "the foreign capture (folder or archive)");
  app.add_option("--foreign-fps", args.foreign_fps,
                 "only the foreign clips captured at this frame rate, at their own rate (e.g. 120 with "
                 "--resample-factors 4: real 120 fps capture given at 30 fps, its new frames scored against the real "
                 "ones); default: every clip, resampled to the model's rate")
      ->check(CLI::PositiveNumber);
  app.add_option("--windows-csv", args.windows_csv,
                 "also write one CSV row per (task row, window, method) of the gap, sparse and resample tables: the "
                 "window's L2P and L2Q and the signals of bench/window_log.h (foreign: the windows of the content "
                 "groups)");
  app.add_option("--features", args.features,
                 "the motion feature extractor (models/evaluation/motion-features.mfm): adds NeMF's FID and diversity "
                 "per task row and method, and of the prior's samples with the sample task (bench/motion_features.h)")
      ->check(CLI::ExistingFile);
  app.add_flag("--no-fallback", args.no_fallback,
               "the latent solvers keep their own result where the prior cannot reach the keys (by default they fall "
               "back to interpolation there: tasks/latent/fallback.h)");
  app.add_flag("--libtorch-energy", args.libtorch_energy,
               "the latent solvers minimise the prior's energy on libtorch (tasks/reference/energies.h) instead of "
               "the Eigen runtime's (tasks/latent/runtime_energy.h), to compare them");
  app.add_flag("--print-stats", args.print_stats,
               "add the table of training statistics (position mean / std, standing heights)");
}

// The checks and defaults that depend on several options.
void resolve(Args& args) {
  const std::vector<std::string> available = mf::available_methods();
  args.methods_given = !args.methods.empty();
  if (args.methods.empty()) args.methods = available;
  for (const std::string& m : args.methods) {
    bool found = false;
    for (const std::string& a : available) found = found || a == m;
    if (!found) {
      std::string list;
      for (const std::string& a : available) list += (list.empty() ? "" : ", ") + a;
      throw mf::InputError("unknown method '" + m + "' (available: " + list + ")");
    }
  }
  args.tasks_given = !args.task_names.empty();
  for (const std::string& t : args.task_names) {
    if (is_prior_task(t)) {
      args.prior_tasks.push_back(t);
    } else {
      args.tasks.push_back(mf::bench::task_from_name(t));
    }
  }
  if (!args.tasks_given) args.tasks = mf::bench::all_tasks();
  if (args.no_model && !args.model.empty()) throw mf::InputError("--model and --no-model exclude each other");
  if (!args.no_model && args.model.empty()) args.model = mf::default_model_path();
  if (!args.tasks_given && !args.model.empty()) args.prior_tasks = kPriorTasks;
  if (!args.prior_tasks.empty() && args.model.empty()) {
    throw mf::InputError("the tasks recon, fps, seams and sample need a model (--model PATH)");
  }
  if (args.rig == "native") args.rig.clear();
  if (args.dataset == "foreign") {
    if (args.model.empty()) throw mf::InputError("--dataset foreign needs the model (its rig anatomy maps the clips)");
    if (!args.rig.empty() || args.trajectory)
      throw mf::InputError("--dataset foreign takes neither --rig nor --trajectory");
    if (!args.prior_tasks.empty() && args.tasks_given)
      throw mf::InputError("--dataset foreign runs the gap, sparse and resample tasks only");
    args.prior_tasks.clear();
  } else if (args.foreign_fps > 0) {
    throw mf::InputError("--foreign-fps needs --dataset foreign");
  }
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// One group of foreign validation clips: its name and clips, with the
// retargeters that score them.
struct ForeignGroup {
  std::string name;
  std::vector<mf::Clip> clips;
  std::vector<std::shared_ptr<const mf::Retargeter>> to_model;
};

std::vector<ForeignGroup> foreign_groups(const std::vector<mf::bench::ForeignClip>& clips, const mf::TaskContext& ctx) {
  std::vector<ForeignGroup> groups;
  auto group = [&](const std::string& name) -> ForeignGroup& {
    for (ForeignGroup& g : groups)
      if (g.name == name) return g;
    groups.push_back({name, {}, {}});
    return groups.back();
  };
  for (const mf::bench::ForeignClip& c : clips) {
    auto r = std::make_shared<const mf::Retargeter>(mf::model_retargeter(c.clip.motion, {}, ctx));
    for (const std::string& name : {"rig " + c.convention, "content: " + c.content}) {
      ForeignGroup& g = group(name);
      g.clips.push_back(c.clip);
      g.to_model.push_back(r);
    }
  }
  return groups;
}

// Real windows of `length` frames (every 40 frames, at most max_windows),
// canonical at their first frame as the prior's samples are, as the real side
// of `set`.
void add_real_windows(const mf::bench::MotionFeatures& extractor, const std::vector<mf::Clip>& clips, int length,
                      int max_windows, const Eigen::Vector3d& root_forward, const std::string& set,
                      mf::bench::FeatureSets* sets) {
  for (const mf::Window& w :
       mf::bench::cap_windows(mf::bench::protocol_windows(clips, length, 40), max_windows)) {
    const mf::Motion raw = clips[w.clip].motion.slice(w.start, w.start + length);
    sets->add_truth(set, extractor.features(mf::bench::canonicalise(raw, 0, root_forward)));
  }
}

// The foreign capture's tables: per task row, L2P of each method and its
// ratio to interpolation's, per group of clips (all, per rig convention, per
// content).
void run_foreign(const Args& args, const mf::TaskContext& ctx, const mf::bench::EvalStats& stats,
                 mf::bench::ProtocolOptions options, const std::function<void(const std::string&)>& emit,
                 mf::bench::WindowLog* log) {
  const double fps = args.foreign_fps > 0 ? args.foreign_fps : ctx.model->config().fps;
  const mf::bench::ForeignData data = mf::bench::load_foreign_data(args.foreign_source, args.data.cache_dir, fps, true);
  std::vector<mf::bench::ForeignClip> clips = args.split.split == "train" ? data.train : data.validation;
  if (args.foreign_fps > 0) {
    clips.erase(std::remove_if(clips.begin(), clips.end(),
                               [&](const mf::bench::ForeignClip& c) { return std::abs(c.source_fps - fps) > 1e-3; }),
                clips.end());
  }
  if (clips.empty()) {
    throw mf::InputError("no foreign clip in the " + args.split.split + " split" +
                         (args.foreign_fps > 0 ? " captured at " + fixed(args.foreign_fps, 0) + " fps" : ""));
  }
  std::ostringstream head;
  head << "### Foreign capture (" << args.split.split << " split: " << clips.size() << " clips)\n\n";
  for (const mf::bench::ForeignClip& c : clips)
    head << "- " << c.clip.name << ": " << c.content << ", " << c.clip.motion.num_joints() << " joints, "
         << fixed(c.source_fps, 0) << " fps given, " << c.clip.motion.num_frames() << " frames at "
         << fixed(c.clip.motion.fps, 0) << " fps\n";
  emit(head.str() + "\n");
  if (log)
    for (const mf::bench::ForeignClip& c : clips) log->set_labels(c.clip.name, {c.convention, c.content});
  const std::vector<ForeignGroup> groups = foreign_groups(clips, ctx);
  std::vector<std::string> methods{"interp"};
  for (const std::string& m : args.methods)
    if (m != "interp") methods.push_back(m);
  options.root_forward = ctx.model->rig().root_forward;
  for (mf::bench::Task task : args.tasks) {
    // results[group][method] = rows
    std::vector<std::vector<mf::bench::TaskResult>> results(groups.size());
    std::vector<std::string> ran;
    for (const std::string& method : methods) {
      if (!mf::bench::method_supports(method, task)) continue;
      ran.push_back(method);
      for (size_t g = 0; g < groups.size(); ++g) {
        std::cerr << "running foreign " << groups[g].name << " / " << mf::bench::task_name(task) << " / " << method
                  << "\n";
        mf::bench::ProtocolOptions o = options;
        o.clip_to_model = groups[g].to_model;
        // The content groups partition the clips: each window is logged once.
        const bool content = groups[g].name.rfind("content: ", 0) == 0;
        o.window_log = content ? log : nullptr;
        if (!content) o.feature_sets = nullptr;
        results[g].push_back(mf::bench::run_task(task, groups[g].clips, stats, method, o, ctx));
        if (o.window_log) o.window_log->write_csv(args.windows_csv);  // so far, in case the run is stopped
      }
    }
    if (ran.empty()) continue;
    const size_t rows = results[0][0].rows.size();
    for (size_t r = 0; r < rows; ++r) {
      const mf::bench::RowResult& first = results[0][0].rows[r];
      std::ostringstream t;
      t << "#### " << mf::bench::task_name(task) << " "
        << (first.label.empty() ? std::to_string(first.parameter) : first.label)
        << ": L2P (ratio to interp), " << at::get_num_threads() << " thread(s)\n\n| group | windows |";
      for (const std::string& m : ran) t << " " << m << " |";
      t << "\n|---|---|";
      for (size_t i = 0; i < ran.size(); ++i) t << "---|";
      t << "\n";
      // "all": the rig groups pooled (they partition the clips; every window of a row has as many frames).
      std::vector<double> pooled(ran.size(), 0.0);
      int pooled_windows = 0;
      for (size_t g = 0; g < groups.size(); ++g) {
        if (groups[g].name.rfind("rig ", 0) != 0) continue;
        const int n = results[g][0].rows[r].metrics.windows;
        pooled_windows += n;
        for (size_t m = 0; m < ran.size(); ++m) pooled[m] += n * results[g][m].rows[r].metrics.l2p;
      }
      auto cells = [&](const std::string& name, int windows, const std::vector<double>& l2p) {
        t << "| " << name << " | " << windows << " |";
        for (size_t m = 0; m < ran.size(); ++m) {
          t << " " << fixed(l2p[m], 3);
          if (m > 0 && l2p[0] > 0) t << " (" << fixed(l2p[m] / l2p[0], 2) << "x)";
          t << " |";
        }
        t << "\n";
      };
      if (pooled_windows > 0) {
        for (double& v : pooled) v /= pooled_windows;
        cells("all (rigs pooled)", pooled_windows, pooled);
      }
      for (size_t g = 0; g < groups.size(); ++g) {
        std::vector<double> l2p;
        for (size_t m = 0; m < ran.size(); ++m) l2p.push_back(results[g][m].rows[r].metrics.l2p);
        cells(groups[g].name, results[g][0].rows[r].metrics.windows, l2p);
      }
      emit(t.str() + "\n");
    }
  }
}

int run(Args& args, const std::string& command) {
  resolve(args);
  mf::set_compute_threads(args.threads);
  const auto run_start = std::chrono::steady_clock::now();

  // The prior, loaded once, frozen, shared by every method and task.
  mf::TaskContext ctx;
  ctx.interpolation_fallback = !args.no_fallback;
  // The libtorch prior: the prior tasks' reconstruction and sampling, and --libtorch-energy.
  std::shared_ptr<const mf::NemfModel> model;
  if (!args.model.empty()) {
    std::cerr << "loading model " << args.model << "\n";
    ctx.model = std::make_shared<const mf::runtime::NemfRuntime>(mf::runtime::NemfRuntime::load(args.model));
    model = std::make_shared<const mf::NemfModel>(mf::load_nemf(args.model));  // frozen
    if (args.libtorch_energy) ctx.reference = mf::libtorch_energies(model);
    mf::bench::load_transformers(args.transformers, args.model, &ctx, true);
    ctx.model_anatomy = mf::load_rig_anatomy_next_to(args.model, ctx.model->rig().skeleton);
  }

  std::cerr << "loading " << args.data.source << "\n";
  const auto t0 = std::chrono::steady_clock::now();
  const mf::Dataset data = mf::bench::load_data(args.data, true);
  std::cerr << "loaded " << data.train.size() << " training and " << data.validation.size()
            << " validation clips in "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() << " s\n";
  if (data.validation.empty()) throw mf::InputError("the validation split of " + args.data.source + " is empty");
  const std::vector<mf::Clip>& clips = args.split.clips(data);

  const mf::bench::EvalStats stats = mf::bench::compute_eval_stats(data.train);
  long validation_frames = 0;
  for (const mf::Clip& c : data.validation) validation_frames += c.motion.num_frames();

  std::ostringstream md;
  md << "## motionfield-bench\n\n";
  md << "- command: `" << command << "`\n";
  md << "- model: " << (model ? args.model + " (" + model->config().describe() + ")" : std::string("none")) << "\n";
  for (const mf::InbetweenerKind& k : mf::inbetweener_kinds()) {
    const std::string& kind = k.name;
    const mf::runtime::InbetweenerRuntime* t = ctx.inbetweener(kind);
    md << "- " << kind << " transformer: " << (t ? t->describe() : std::string("not loaded")) << "\n";
  }
  md << "- validation clips: " << data.validation.size() << " (" << validation_frames << " frames)"
     << ", training clips: " << data.train.size() << "\n";
  md << "- tables measured on the " << args.split.split << " split\n";
  md << "- L2P statistics: " << stats.windows << " training windows of 50 frames every 20, canonicalised at frame 9\n";
  md << "- standing heights (median of per-clip 5th percentiles, training split):";
  for (size_t i = 0; i < stats.feet.size(); ++i) {
    md << (i ? ", " : " ") << data.skeleton.names[stats.feet[i].joint] << " " << fixed(100.0 * stats.standing_height[i], 2)
       << " cm (threshold " << fixed(stats.feet[i].threshold_cm, 0) << " cm)";
  }
  md << "\n- torch threads: " << at::get_num_threads();
  if (args.split.max_windows > 0) md << ", at most " << args.split.max_windows << " windows per row";
  md << "\n\n";
  if (args.print_stats) md << "### Training statistics\n\n" << mf::bench::format_eval_stats(stats) << "\n";
  std::cout << md.str() << std::flush;

  auto emit = [&](const std::string& text) {
    std::cout << text << std::flush;
    md << text;
  };
  mf::bench::ProtocolOptions options;
  options.max_windows = args.split.max_windows;
  options.rig = args.rig;
  options.rig_anatomy = ctx.model_anatomy;
  if (!args.gaps.empty()) options.gap_lengths = args.gaps;
  if (!args.spacings.empty()) options.keyframe_spacings = args.spacings;
  if (!args.resample_factors.empty() || !args.resample_ratios.empty()) {
    options.resample_ratios.clear();
    for (int k : args.resample_factors) options.resample_ratios.push_back({k, 1});
    for (const std::string& r : args.resample_ratios) options.resample_ratios.push_back(mf::bench::parse_resample_ratio(r));
  }
  options.trajectory = args.trajectory;
  options.l2t = args.l2t || args.trajectory;
  if (!args.rig.empty()) emit("- rig: " + args.rig + " (bench/synthetic_rigs.h)\n\n");
  mf::bench::WindowLog window_log(args.dataset, {args.rig.empty() ? "native" : args.rig, ""});
  if (!args.windows_csv.empty()) options.window_log = &window_log;
  std::unique_ptr<mf::bench::MotionFeatures> extractor;
  mf::bench::FeatureSets feature_sets;
  if (!args.features.empty()) {
    extractor = std::make_unique<mf::bench::MotionFeatures>(args.features);
    options.features = extractor.get();
    options.feature_sets = &feature_sets;
  }
  if (args.dataset == "foreign") {
    run_foreign(args, ctx, stats, options, emit, options.window_log);
    args.tasks.clear();
  }
  for (mf::bench::Task task : args.tasks) {
    for (const std::string& method : args.methods) {
      if (!mf::bench::method_supports(method, task)) {
        // Only worth a note when the method was asked for by name.
        if (args.methods_given) {
          emit("Method `" + method + "` does not support the " + mf::bench::task_name(task) + " task: skipped.\n\n");
        }
        continue;
      }
      bool needs_model = false, constrained = false;
      std::string needs_inbetweener;
      for (const mf::Method& m : mf::registered_methods()) {
        if (m.name != method) continue;
        needs_model = m.needs_model;
        needs_inbetweener = m.needs_inbetweener;
        constrained = static_cast<bool>(m.complete_constrained);
      }
      if (args.trajectory && task == mf::bench::Task::Gap && !constrained) {
        if (args.methods_given) emit("Method `" + method + "` cannot take a trajectory: skipped.\n\n");
        continue;
      }
      if (needs_model && !ctx.model) {
        emit("Method `" + method + "` needs a model and none was given (--model PATH): skipped on the " +
             mf::bench::task_name(task) + " task.\n\n");
        continue;
      }
      if (!needs_inbetweener.empty() && !ctx.inbetweener(needs_inbetweener)) {
        if (args.methods_given) {
          emit("Method `" + method + "` needs the " + needs_inbetweener + " transformer (" +
               mf::inbetweener_file_name(needs_inbetweener) + " next to the model, or --" + needs_inbetweener +
               " PATH): skipped.\n\n");
        }
        continue;
      }
      std::cerr << "running " << mf::bench::task_name(task) << " / " << method << "\n";
      const mf::bench::TaskResult result = mf::bench::run_task(task, clips, stats, method, options, ctx);
      emit(mf::bench::format_table(result, args.l2p_axes) + "\n");
      if (options.window_log) window_log.write_csv(args.windows_csv);  // so far, in case the run is stopped
    }
  }

  mf::bench::PriorEvalOptions prior_options;
  prior_options.max_windows = args.split.max_windows;
  prior_options.samples = args.samples;
  prior_options.seed = static_cast<uint64_t>(args.seed);
  const std::shared_ptr<const mf::runtime::NemfRuntime> codec_runtime = ctx.model;
  for (const std::string& task : args.prior_tasks) {
    std::cerr << "running " << task << " / prior\n";
    const auto t0 = std::chrono::steady_clock::now();
    std::string table;
    if (task == "recon") {
      table = mf::bench::format_recon(mf::bench::run_recon(*model, *codec_runtime, clips, stats, prior_options));
    } else if (task == "fps") {
      table = mf::bench::format_fps(mf::bench::run_fps(*codec_runtime, clips, prior_options));
    } else if (task == "seams") {
      table = mf::bench::format_seams(mf::bench::run_seams(*codec_runtime, clips, prior_options),
                                      prior_options.seam_radius);
    } else {
      if (extractor) {
        add_real_windows(*extractor, clips, model->config().window, prior_options.max_windows,
                         model->rig().root_forward, "prior samples", &feature_sets);
        prior_options.on_sample = [&](const mf::Motion& m) {
          feature_sets.add_generated("prior samples", extractor->features(m));
        };
      }
      table = mf::bench::format_sample(
          mf::bench::run_sample(*model, clips, data.train, stats, prior_options));
    }
    emit(table + "\nTask wall time: " + fixed(seconds_since(t0), 1) + " s.\n\n");
  }
  if (extractor) {
    emit("### Distribution metrics (NeMF's FID and diversity; features: " + args.features +
         ")\n\n" + feature_sets.table() + "\n");
  }
  emit("Total wall time: " + fixed(seconds_since(run_start), 1) + " s.\n");

  if (!args.out.empty()) {
    std::ofstream f(args.out);
    f << md.str();
    if (!f) throw std::runtime_error("cannot write " + args.out);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return mf::bench::benchmark_main<Args>(
      argc, argv, "motionfield-bench",
      "The LaFAN1-style benchmark of docs/BENCHMARKS.md: markdown tables of every (task, method) pair.", add_options,
      run);
}
