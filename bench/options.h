// Command-line option groups shared by the benchmark programs, on CLI11
// (prior/util/command_line.h runs them with the tools' exit codes): the
// transformer files, the data set and its split, the thread count, lists and
// numeric overrides of solver settings. Each group adds its options to a
// CLI::App and fills a small struct whose defaults are the documented ones;
// load_bench_context() loads what the benchmarks on the learned models start from.
#pragma once

#include <CLI/CLI.hpp>

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "bench/metrics.h"
#include "prior/data/dataset.h"
#include "prior/util/command_line.h"
#include "tasks/context/task_context.h"

namespace mf::bench {

/// --<kind> PATH for every in-betweener kind (--twostage, --citl): the
/// in-betweener files by kind; a kind not given means its file next to the
/// model, when it exists (mf::inbetweener_path_next_to).
struct TransformerFiles {
  std::map<std::string, std::string> by_kind;
};
void add_transformer_options(CLI::App& app, TransformerFiles& files);
/// Loads the in-betweeners of `files` (or next to `model_path`) into `models`
/// (checked against its prior's skeleton when it has one) with the model-set
/// loader (tasks/transformer/inbetweener_files.h load_inbetweeners, strict: a file that
/// does not load is an error), logging each file to stderr when `verbose`.
void load_transformers(const TransformerFiles& files, const std::string& model_path, ModelSet* models, bool verbose);

/// --source PATH, --cache-dir DIR: the clips (a BVH folder or archive) and the
/// extraction and parse cache.
struct DataSource {
  std::string source = default_train_archive();
  std::string cache_dir = default_cache_dir();
};
void add_data_options(CLI::App& app, DataSource& data);
/// Loads `data` through the data pipeline (prior/data/dataset.h).
Dataset load_data(const DataSource& data, bool verbose);

/// --split validation|train|validation-mirror, --max-windows N: the clips the
/// tables are measured on (tune on train, report on validation;
/// validation-mirror: every validation clip's left/right mirror, motion of
/// another distribution than the training split's) and how many windows per
/// table row at most (0 = all).
struct SplitChoice {
  std::string split = "validation";
  int max_windows = 0;
  /// The chosen split of `data`.
  const std::vector<Clip>& clips(const Dataset& data) const;

 private:
  mutable std::vector<Clip> mirrored_;
};
void add_split_options(CLI::App& app, SplitChoice& choice);

/// --threads N (N >= 1): torch's intra-op threads; `threads` holds the default.
/// With it --gemm kernels|blas|eigen: who multiplies the runtime's matrices
/// (set_gemm_backend, prior/runtime/tensor_ops.h), for comparisons.
void add_threads_option(CLI::App& app, int& threads);

/// What every benchmark on the protocol's clips with the learned models takes:
/// --model (the prior; "" = the default model), the data, the split, the
/// transformer files and --threads.
struct ModelBenchOptions {
  std::string model;
  DataSource data;
  SplitChoice split;
  TransformerFiles transformers;
  int threads = 1;
  bool libtorch_energy = false;  ///< --libtorch-energy: the libtorch reference energies in the context
};
void add_model_bench_options(CLI::App& app, ModelBenchOptions& options);

/// What a benchmark of ModelBenchOptions runs with (load_bench_context()).
struct BenchContext {
  std::string model_path;  ///< --model, or the default model
  /// The prior (frozen), its rig anatomy (kRigAnatomyFileName next to it, as
  /// mf_model_load loads it: clips on another rig than the model's are
  /// retargeted) and the in-betweeners.
  TaskContext ctx;
  Dataset data;
  EvalStats stats;  ///< of data.train, for the metrics
};

/// The start of every such benchmark: the model path (the default model when
/// --model is not given; InputError "no default model: pass --model FILE"
/// when there is none), torch's threads (options.threads), the models (the
/// in-betweeners strictly, quietly: load_transformers()), the data (quietly)
/// and the statistics. The split's clips are options.split.clips(data).
BenchContext load_bench_context(const ModelBenchOptions& options);

/// A comma-separated list, e.g. "--methods interp,nemf" or "--lengths 5,15":
/// one argument per occurrence, split at the commas and converted to T.
template <class T>
CLI::Option* add_list_option(CLI::App& app, const std::string& name, std::vector<T>& values,
                             const std::string& help) {
  return app.add_option(name, values, help)
      ->delimiter(',')
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
}

/// One "--NAME X" option per (NAME, help) pair, in the group `group` of the
/// help; a given value is stored in numbers[NAME] (absent when not given, so
/// that the settings' own defaults apply).
using NamedHelp = std::vector<std::pair<std::string, std::string>>;
void add_number_options(CLI::App& app, std::map<std::string, double>& numbers, const NamedHelp& options,
                        const std::string& group);

/// Moves numbers[key], when given, into *field (converted to its type) and
/// erases it, so that what is left over at the end was not used.
template <class T>
void take_number(std::map<std::string, double>& numbers, const char* key, T* field) {
  auto it = numbers.find(key);
  if (it == numbers.end()) return;
  *field = static_cast<T>(it->second);
  numbers.erase(it);
}

/// "program arg1 arg2 ..." for the header of a report.
std::string command_line(const std::string& program, int argc, char** argv);

/// The main() of a benchmark program `name`: its options fill an `Args`
/// (add_options(app, args)), then run(args, command_line(...)) is its body,
/// with the exit codes of mf::cli::run.
template <class Args>
int benchmark_main(int argc, char** argv, const std::string& name, const std::string& description,
                   void (*add_options)(CLI::App&, Args&), int (*run)(Args&, const std::string&)) {
  Args args;
  CLI::App app{description, name};
  mf::cli::use_tool_defaults(app);
  add_options(app, args);
  return mf::cli::run(app, argc, argv, [&] { return run(args, command_line(name, argc, argv)); });
}

}  // namespace mf::bench
