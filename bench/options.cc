#include "bench/options.h"

#include <iostream>
#include <memory>

#include "prior/inbetween/inbetweener_kinds.h"
#include "prior/model/model_file.h"
#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/rig/mirror.h"
#include "prior/runtime/nemf_runtime.h"
#include "prior/runtime/tensor_ops.h"
#include "prior/util/command_line.h"
#include "prior/util/threads.h"
#include "tasks/context/model_rig.h"
#include "tasks/reference/libtorch_energies.h"
#include "tasks/transformer/inbetweener_files.h"

namespace mf::bench {

void add_transformer_options(CLI::App& app, TransformerFiles& files) {
  for (const InbetweenerKind& kind : inbetweener_kinds()) {
    std::string methods;
    for (const InbetweenerStage& s : kind.stages) methods += (methods.empty() ? "" : ", ") + s.name + ", nemf-" + s.name;
    app.add_option("--" + kind.name, files.by_kind[kind.name],
                   "the " + kind.title + " (methods " + methods + "; default: " + kind.file_name +
                       " next to the model, if present)");
  }
}

void load_transformers(const TransformerFiles& files, const std::string& model_path, ModelSet* models, bool verbose) {
  InbetweenerLog log;
  if (verbose)
    log = [](const std::string& title, const std::string& path) { std::cerr << "loading " << title << " " << path << "\n"; };
  load_inbetweeners(model_path, files.by_kind, true, models, log);
}

void add_data_options(CLI::App& app, DataSource& data) {
  app.add_option("--source", data.source, "BVH folder or .tar/.tar.xz/.tar.gz archive (default: the shared training "
                                          "archive)");
  app.add_option("--cache-dir", data.cache_dir, "extraction and parse cache (default: <project>/.cache)");
}

Dataset load_data(const DataSource& data, bool verbose) {
  DatasetOptions options;
  options.source = data.source;
  options.cache_dir = data.cache_dir;
  options.verbose = verbose;
  return load_dataset(options);
}

const std::vector<Clip>& SplitChoice::clips(const Dataset& data) const {
  if (split == "train") return data.train;
  if (split != "validation-mirror") return data.validation;
  if (mirrored_.empty()) {
    // The twists of the mirror are chosen from the training split's statistics, as in training.
    std::vector<const Motion*> motions;
    for (const Clip& c : data.train) motions.push_back(&c.motion);
    const MirrorMap map = mirror_map(data.skeleton, mean_local_rotations(motions));
    for (const Clip& c : data.validation) mirrored_.push_back({c.name + "#mirror", mirror_motion(c.motion, map)});
  }
  return mirrored_;
}

void add_split_options(CLI::App& app, SplitChoice& choice) {
  app.add_option("--split", choice.split,
                 "validation, train or validation-mirror (the validation clips' left/right mirrors): the clips "
                 "the tables are measured on (tune on train)")
      ->check(CLI::IsMember({"validation", "train", "validation-mirror"}));
  app.add_option("--max-windows", choice.max_windows, "at most N windows per table row, spread evenly (0: all)")
      ->check(mf::cli::at_least(0));
}

void add_threads_option(CLI::App& app, int& threads) {
  app.add_option("--threads", threads, "torch intra-op threads")->check(mf::cli::at_least(1));
  app.add_option_function<std::string>(
         "--gemm",
         [](const std::string& name) {
           runtime::set_gemm_backend(name == "blas"    ? runtime::GemmBackend::Blas
                                     : name == "eigen" ? runtime::GemmBackend::Eigen
                                                       : runtime::GemmBackend::Kernels);
         },
         "who multiplies the runtime's matrices: kernels (the runtime's own; the default where the CPU has AVX2 + "
         "FMA or AVX-512), blas, eigen (prior/runtime/tensor_ops.h)")
      ->check(CLI::IsMember({"kernels", "blas", "eigen"}));
}

void add_model_bench_options(CLI::App& app, ModelBenchOptions& options) {
  app.add_option("--model", options.model, "the prior (default: the default model)");
  add_data_options(app, options.data);
  add_split_options(app, options.split);
  add_transformer_options(app, options.transformers);
  add_threads_option(app, options.threads);
  app.add_flag("--libtorch-energy", options.libtorch_energy,
               "the latent solvers minimise the prior's energy on libtorch (tasks/reference/), not on the Eigen "
               "runtime (for comparisons)");
}

BenchContext load_bench_context(const ModelBenchOptions& options) {
  BenchContext b;
  b.model_path = options.model.empty() ? default_model_path() : options.model;
  if (b.model_path.empty()) throw InputError("no default model: pass --model FILE");
  set_compute_threads(options.threads);
  b.ctx.model = std::make_shared<const runtime::NemfRuntime>(runtime::NemfRuntime::load(b.model_path));
  if (options.libtorch_energy)
    b.ctx.reference = libtorch_energies(std::make_shared<const NemfModel>(load_nemf(b.model_path)));  // frozen
  load_transformers(options.transformers, b.model_path, &b.ctx, false);
  b.ctx.model_anatomy = load_rig_anatomy_next_to(b.model_path, b.ctx.model->rig().skeleton);
  b.data = load_data(options.data, false);
  b.stats = compute_eval_stats(b.data.train);
  return b;
}

void add_number_options(CLI::App& app, std::map<std::string, double>& numbers, const NamedHelp& options,
                        const std::string& group) {
  for (const auto& [name, help] : options) {
    app.add_option_function<double>(
           "--" + name, [&numbers, name = name](double value) { numbers[name] = value; }, help)
        ->group(group);
  }
}

std::string command_line(const std::string& program, int argc, char** argv) {
  std::string command = program;
  for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
  return command;
}

}  // namespace mf::bench
