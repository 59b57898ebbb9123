// motionfield-bench: the LaFAN1-style benchmark of docs/BENCHMARKS.md. Loads the
// data set, computes the evaluation statistics on the training split, loads the
// prior once (shared by every method that needs it), runs every (task, method)
// pair on the validation split and the prior's own evaluation (recon, fps,
// seams, sample), and prints markdown tables.
#include <ATen/Parallel.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bench/metrics.h"
#include "bench/text.h"
#include "bench/prior_eval.h"
#include "bench/protocol.h"
#include "prior/data/dataset.h"
#include "prior/model/model_file.h"
#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/inbetween/inbetweener.h"
#include "bench/synthetic_rigs.h"
#include "tasks/jobs.h"
#include "tasks/model_rig.h"
#include "tasks/transformer_methods.h"
#include "prior/util/threads.h"

namespace {

using mf::bench::fixed;
using mf::bench::split_list;

const char* kUsage =
    "usage: motionfield-bench [options]\n"
    "  --methods a,b     methods to run (default: every available method)\n"
    "  --tasks a,b       gap, sparse, resample, and with a model recon, fps, seams, sample\n"
    "                    (default: gap, sparse, resample, plus the prior's four when a model is loaded)\n"
    "  --model PATH      the prior (default: the default model, see mf::default_model_path())\n"
    "  --no-model        run without a prior (methods that need one are skipped)\n"
    "  --twostage PATH   the two-stage transformer (methods context, detail, nemf-context, nemf-detail;\n"
    "                    default: motionfield-twostage.mfm next to the model, if present)\n"
    "  --citl PATH       the CITL transformer (methods citl, nemf-citl; default: motionfield-citl.mfm\n"
    "                    next to the model, if present)\n"
    "  --samples N       windows drawn for the sample task (default 256)\n"
    "  --seed N          seed of the sample task (default 1)\n"
    "  --threads N       torch intra-op threads (default 2)\n"
    "  --source PATH     BVH folder or archive (default: the shared training archive)\n"
    "  --cache-dir DIR   extraction and parse cache (default: <project>/.cache)\n"
    "  --max-windows N   at most N windows per table row, spread evenly (default: all)\n"
    "  --split NAME      validation (default) or train: the clips the tables are measured on (tune on train)\n"
    "  --rig NAME        gap and sparse tables on a synthetic rig (mixamo, cmu, lafan1, unreal, rigify, smpl;\n"
    "                    bench/synthetic_rigs.h): each window rewritten onto it, solved there, brought back;\n"
    "                    needs motionfield-rig.json next to the model (default: native)\n"
    "  --out FILE        also write the markdown to FILE\n"
    "  --l2p-axes        add columns splitting L2P into horizontal (x, z) and vertical (y) parts\n"
    "  --print-stats     add the table of training statistics (position mean / std, standing heights)\n"
    "  --help            this text\n";

int parse_int(const std::string& flag, const std::string& value, int min_value) {
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(value.c_str(), &end, 10);
  if (value.empty() || *end != '\0' || errno != 0 || v < min_value || v > 1000000) {
    throw mf::InputError(flag + " expects an integer >= " + std::to_string(min_value) + ", got '" + value + "'");
  }
  return static_cast<int>(v);
}

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
  std::vector<mf::bench::Task> tasks;
  std::vector<std::string> prior_tasks;
  bool tasks_given = false;
  std::string model;
  std::string twostage, citl;  // transformer files (default: next to the model)
  bool no_model = false;
  int samples = 256;
  int seed = 1;
  int threads = 2;
  std::string source;
  std::string cache_dir;
  int max_windows = 0;
  std::string split = "validation";
  std::string rig;
  std::string out;
  bool l2p_axes = false;
  bool print_stats = false;
};

Args parse_args(int argc, char** argv) {
  Args args;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "--help" || flag == "-h") {
      std::cout << kUsage;
      std::exit(0);
    }
    if (flag == "--l2p-axes") {
      args.l2p_axes = true;
      continue;
    }
    if (flag == "--print-stats") {
      args.print_stats = true;
      continue;
    }
    if (flag == "--no-model") {
      args.no_model = true;
      continue;
    }
    if (i + 1 >= argc) throw mf::InputError("unknown flag or missing value: " + flag + "\n" + kUsage);
    const std::string value = argv[++i];
    if (flag == "--methods") {
      args.methods = split_list(value);
      args.methods_given = true;
    } else if (flag == "--tasks") {
      args.tasks.clear();
      args.prior_tasks.clear();
      args.tasks_given = true;
      for (const std::string& t : split_list(value)) {
        if (is_prior_task(t)) {
          args.prior_tasks.push_back(t);
        } else {
          args.tasks.push_back(mf::bench::task_from_name(t));
        }
      }
    } else if (flag == "--model") {
      args.model = value;
    } else if (flag == "--twostage") {
      args.twostage = value;
    } else if (flag == "--citl") {
      args.citl = value;
    } else if (flag == "--samples") {
      args.samples = parse_int(flag, value, 1);
    } else if (flag == "--seed") {
      args.seed = parse_int(flag, value, 0);
    } else if (flag == "--threads") {
      args.threads = parse_int(flag, value, 1);
    } else if (flag == "--source") {
      args.source = value;
    } else if (flag == "--cache-dir") {
      args.cache_dir = value;
    } else if (flag == "--rig") {
      if (value != "native") mf::bench::rig_variant(value);  // validates the name
      args.rig = value == "native" ? "" : value;
    } else if (flag == "--split") {
      if (value != "validation" && value != "train") throw mf::InputError("--split: validation or train, not '" + value + "'");
      args.split = value;
    } else if (flag == "--max-windows") {
      args.max_windows = parse_int(flag, value, 0);
    } else if (flag == "--out") {
      args.out = value;
    } else {
      throw mf::InputError("unknown flag " + flag + "\n" + kUsage);
    }
  }
  const std::vector<std::string> available = mf::available_methods();
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
  if (!args.tasks_given) args.tasks = mf::bench::all_tasks();
  if (args.no_model && !args.model.empty()) throw mf::InputError("--model and --no-model exclude each other");
  if (!args.no_model && args.model.empty()) args.model = mf::default_model_path();
  if (!args.tasks_given && !args.model.empty()) args.prior_tasks = kPriorTasks;
  if (!args.prior_tasks.empty() && args.model.empty()) {
    throw mf::InputError("the tasks recon, fps, seams and sample need a model (--model PATH)");
  }
  if (args.source.empty()) args.source = mf::default_train_archive();
  if (args.cache_dir.empty()) args.cache_dir = mf::default_cache_dir();
  return args;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int run(int argc, char** argv) {
  const Args args = parse_args(argc, argv);
  mf::set_compute_threads(args.threads);
  const auto run_start = std::chrono::steady_clock::now();
  std::string command = "motionfield-bench";
  for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];

  // The prior, loaded once, frozen, shared by every method and task.
  mf::TaskContext ctx;
  std::shared_ptr<mf::NemfModel> model;
  if (!args.model.empty()) {
    std::cerr << "loading model " << args.model << "\n";
    model = std::make_shared<mf::NemfModel>(mf::load_nemf(args.model));
    model->set_requires_grad(false);
    ctx.model = model;
    for (const std::string kind : {mf::kTwoStageKind, mf::kCitlKind}) {
      const std::string given = kind == mf::kCitlKind ? args.citl : args.twostage;
      const std::string path = given.empty() ? mf::inbetweener_path_next_to(args.model, kind) : given;
      if (given.empty() && !std::ifstream(path)) continue;
      std::cerr << "loading transformer " << path << "\n";
      (kind == mf::kCitlKind ? ctx.citl : ctx.twostage) = mf::load_frozen_inbetweener(path, kind);
    }
    ctx.model_anatomy = mf::load_rig_anatomy_next_to(args.model, model->rig().skeleton);
  }

  mf::DatasetOptions data_options;
  data_options.source = args.source;
  data_options.cache_dir = args.cache_dir;
  data_options.verbose = true;
  std::cerr << "loading " << args.source << "\n";
  const auto t0 = std::chrono::steady_clock::now();
  const mf::Dataset data = mf::load_dataset(data_options);
  std::cerr << "loaded " << data.train.size() << " training and " << data.validation.size()
            << " validation clips in "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() << " s\n";
  if (data.validation.empty()) throw mf::InputError("the validation split of " + args.source + " is empty");
  const std::vector<mf::Clip>& clips = args.split == "train" ? data.train : data.validation;

  const mf::bench::EvalStats stats = mf::bench::compute_eval_stats(data.train);
  long validation_frames = 0;
  for (const mf::Clip& c : data.validation) validation_frames += c.motion.num_frames();

  std::ostringstream md;
  md << "## motionfield-bench\n\n";
  md << "- command: `" << command << "`\n";
  md << "- model: " << (model ? args.model + " (" + model->config().describe() + ")" : std::string("none")) << "\n";
  for (const char* kind : {mf::kTwoStageKind, mf::kCitlKind}) {
    const mf::InbetweenModel* t = ctx.inbetweener(kind);
    md << "- " << kind << " transformer: " << (t ? t->describe() : std::string("not loaded")) << "\n";
  }
  md << "- validation clips: " << data.validation.size() << " (" << validation_frames << " frames)"
     << ", training clips: " << data.train.size() << "\n";
  md << "- tables measured on the " << args.split << " split\n";
  md << "- L2P statistics: " << stats.windows << " training windows of 50 frames every 20, canonicalised at frame 9\n";
  md << "- standing heights (median of per-clip 5th percentiles, training split):";
  for (size_t i = 0; i < stats.feet.size(); ++i) {
    md << (i ? ", " : " ") << data.skeleton.names[stats.feet[i].joint] << " " << fixed(100.0 * stats.standing_height[i], 2)
       << " cm (threshold " << fixed(stats.feet[i].threshold_cm, 0) << " cm)";
  }
  md << "\n- torch threads: " << at::get_num_threads();
  if (args.max_windows > 0) md << ", at most " << args.max_windows << " windows per row";
  md << "\n\n";
  if (args.print_stats) md << "### Training statistics\n\n" << mf::bench::format_eval_stats(stats) << "\n";
  std::cout << md.str() << std::flush;

  auto emit = [&](const std::string& text) {
    std::cout << text << std::flush;
    md << text;
  };
  mf::bench::ProtocolOptions options;
  options.max_windows = args.max_windows;
  options.rig = args.rig;
  options.rig_anatomy = ctx.model_anatomy;
  if (!args.rig.empty()) emit("- rig: " + args.rig + " (bench/synthetic_rigs.h)\n\n");
  for (mf::bench::Task task : args.tasks) {
    for (const std::string& method : args.methods) {
      if (!mf::bench::method_supports(method, task)) {
        // Only worth a note when the method was asked for by name.
        if (args.methods_given) {
          emit("Method `" + method + "` does not support the " + mf::bench::task_name(task) + " task: skipped.\n\n");
        }
        continue;
      }
      bool needs_model = false;
      std::string needs_inbetweener;
      for (const mf::Method& m : mf::registered_methods()) {
        if (m.name != method) continue;
        needs_model = m.needs_model;
        needs_inbetweener = m.needs_inbetweener;
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
    }
  }

  mf::bench::PriorEvalOptions prior_options;
  prior_options.max_windows = args.max_windows;
  prior_options.samples = args.samples;
  prior_options.seed = static_cast<uint64_t>(args.seed);
  for (const std::string& task : args.prior_tasks) {
    std::cerr << "running " << task << " / prior\n";
    const auto t0 = std::chrono::steady_clock::now();
    std::string table;
    if (task == "recon") {
      table = mf::bench::format_recon(mf::bench::run_recon(*model, clips, stats, prior_options));
    } else if (task == "fps") {
      table = mf::bench::format_fps(mf::bench::run_fps(*model, clips, prior_options));
    } else if (task == "seams") {
      table = mf::bench::format_seams(mf::bench::run_seams(*model, clips, prior_options),
                                      prior_options.seam_radius);
    } else {
      table = mf::bench::format_sample(
          mf::bench::run_sample(*model, clips, data.train, stats, prior_options));
    }
    emit(table + "\nTask wall time: " + fixed(seconds_since(t0), 1) + " s.\n\n");
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
  try {
    return run(argc, argv);
  } catch (const mf::InputError& e) {
    std::cerr << "motionfield-bench: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "motionfield-bench: error: " << e.what() << "\n";
    return 1;
  }
}
