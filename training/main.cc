// motionfield-train: trains motionfield's models from a folder or archive of BVH files.
//
//   motionfield-train prior --out DIR [--data PATH] [--config FILE] [--width N] [--layers N]
//                           [--zl N] [--zg N] [--max-minutes M] [--seed S] [--threads N] [--resume] ...
//   motionfield-train twostage|citl|keyframe --out DIR [--data PATH] [--hp key=value]... [--config FILE]
//                           [--max-minutes M] [--seed S] [--threads N] [--resume] [--export PATH] ...
//   motionfield-train rig --out FILE.json [--data PATH] [--cache-dir DIR] [--stride N]
//
// Data-parallel training (prior and in-betweeners; training/data_parallel.h):
// start one process per rank with --world-size N --rank R --master ADDR:PORT
// (or torchrun's WORLD_SIZE, RANK, MASTER_ADDR, MASTER_PORT), the same other
// options everywhere; rank 0 writes the output folder.
//
// `motionfield-train <command> --help` lists every option with its default.
// --config FILE holds "key = value" lines ('#' starts a comment) with the
// command's option names without "--"; an option given on the command line
// takes precedence over the file. For twostage and citl any other key (and
// "hp = KEY=VALUE") is a model hyperparameter.
//
// Exit codes: 0 ok, 2 bad input, 1 internal error (prior/util/command_line.h).
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "prior/data/dataset.h"
#include "prior/inbetween/inbetweener.h"
#include "prior/model/model_file.h"
#include "prior/motion/errors.h"
#include "prior/rig/retarget.h"
#include "prior/util/command_line.h"
#include "training/inbetween_trainer.h"
#include "training/prior_trainer.h"

namespace {

// What every training command has besides its trainer's options.
struct RunArgs {
  std::string config;       // --config FILE
  std::string export_path;  // --export PATH
  bool quiet = false;
};

// Data-parallel training: `d` holds the environment's defaults (torchrun's variables).
void add_distributed_options(CLI::App& cmd, mf::DistributedOptions& d) {
  const std::string group = "Several processes or hosts (training/data_parallel.h)";
  cmd.add_option("--world-size", d.world_size, "number of training processes (default: $WORLD_SIZE or 1)")
      ->group(group);
  cmd.add_option("--rank", d.rank, "this process, 0 .. world size - 1; rank 0 writes the output (default: $RANK or 0)")
      ->group(group);
  cmd.add_option_function<std::string>(
         "--master", [&d](const std::string& address) { d.set_master(address); },
         "ADDR:PORT of rank 0's rendezvous (default: $MASTER_ADDR:$MASTER_PORT or 127.0.0.1:29500)")
      ->default_str(d.master_addr + ":" + std::to_string(d.master_port))
      ->group(group);
  cmd.add_option("--dist-timeout", d.timeout_seconds,
                 "seconds to wait for the other processes at the start and at each step before stopping with an error")
      ->group(group);
}

// The options the prior's and the in-betweeners' trainers share (same names in
// both option structs).
template <class Options>
void add_run_options(CLI::App& cmd, Options& o, RunArgs& run) {
  o.data = mf::default_train_archive();
  o.cache_dir = mf::default_cache_dir();
  cmd.add_option("--out", o.out_dir, "output folder: checkpoints, log.csv (required)");
  cmd.add_option("--data", o.data, "folder or .tar/.tar.xz/.tar.gz of BVH files (default: the shared training archive)");
  cmd.add_option("--cache-dir", o.cache_dir, "extraction and parse cache (default: <project>/.cache)");
  cmd.add_option("--max-minutes", o.max_minutes, "wall-time budget, counting earlier runs when resuming");
  cmd.add_option("--max-epochs", o.max_epochs, "at most this many epochs");
  cmd.add_option("--max-steps", o.max_steps, "at most this many optimiser steps (0 = unlimited)");
  cmd.add_option("--batch", o.batch, "windows per step");
  cmd.add_option("--lr", o.lr, "learning rate (Adam)");
  cmd.add_option("--lr-final", o.lr_final, "learning rate at the end of the cosine decay");
  cmd.add_option("--seed", o.seed, "random seed");
  cmd.add_option("--threads", o.threads,
                 "torch intra-op threads (1 when anything else runs: 30 steps took 1.4x less time on 2 threads than "
                 "on 1 on an idle machine, 3.4x more with one busy process; docs/BENCHMARKS.md, \"Threads\")");
  cmd.add_option("--max-train-clips", o.max_train_clips, "use at most N training clips (0 = all)");
  cmd.add_flag("--mirror", o.augmentation.mirror,
               "also train on every training clip's left/right mirror (doubles the data; give it again on --resume)");
  cmd.add_option("--frame-noise", o.augmentation.frame_noise_degrees,
                 "also train on every clip (and mirror) with each joint's frame turned by a constant random "
                 "rotation of at most DEG degrees (a retarget's anatomy errors, other bodies; doubles the data; "
                 "give it again on --resume)");
  cmd.add_option("--speeds", o.augmentation.speeds,
                 "also train on every training clip played at these speeds, e.g. 0.8,1.25 (time warp, each in "
                 "[0.5, 2]; give them again on --resume)")
      ->delimiter(',');
  cmd.add_flag("--resume", o.resume, "continue from DIR/last.* if present");
  cmd.add_option("--init", o.init_from,
                 "start a new run from this model's weights and statistics (same sizes and skeleton), not random ones; "
                 "an in-betweener's --hp may add parameters to it (twostage: --hp interp_input=1)");
  cmd.add_option("--export", run.export_path, "copy the best checkpoint to PATH at the end");
  cmd.add_flag("--quiet", run.quiet, "no progress lines on stderr");
  add_distributed_options(cmd, o.distributed);
}

void add_prior_options(CLI::App& cmd, mf::PriorTrainingOptions& o, RunArgs& run) {
  cmd.add_option("--config", run.config, "key = value lines, same keys as the options without '--'");
  add_run_options(cmd, o, run);
  mf::NemfConfig& c = o.config;
  const std::string sizes = "Model sizes (prior/model/nemf.h)";
  cmd.add_option("--width", c.decoder_width, "decoder width")->group(sizes);
  cmd.add_option("--layers", c.decoder_layers, "decoder layers")->group(sizes);
  cmd.add_option("--zl", c.zl, "local latent size")->group(sizes);
  cmd.add_option("--zg", c.zg, "global (root orientation) latent size")->group(sizes);
  cmd.add_option("--zg-layers", c.zg_layers, "the last decoder layers that also take z_g")->group(sizes);
  cmd.add_option("--encoder-channels", c.encoder_channels, "per-joint channels of the first skeleton convolution")
      ->group(sizes);
  cmd.add_option("--pe", c.pe_frequencies, "positional-encoding octaves")->group(sizes);
  cmd.add_option("--gmp-width", c.gmp_width, "global motion predictor width")->group(sizes);
  cmd.add_option("--gmp-kernel", c.gmp_kernel, "global motion predictor kernel")->group(sizes);
  cmd.add_option("--gmp-blocks", c.gmp_blocks, "global motion predictor blocks")->group(sizes);
  cmd.add_flag("--gmp-only", o.gmp_only,
               "train only the global motion predictor, of the --gmp-* sizes, on the --init model's frozen VAE "
               "(its GMP is kept if the sizes are the same, else a fresh one; the best checkpoint: lowest "
               "validation translation error; give it again on --resume)");
  cmd.add_option("--gmp-reconstructed", o.gmp_reconstructed,
                 "with --gmp-only: the share in [0, 1] of windows whose GMP inputs are the VAE's reconstruction "
                 "instead of the captured motion (give it again on --resume)");
  cmd.add_flag("--steering-gmp", c.steering_gmp,
               "with --gmp-only: keep the --init model's GMP, frozen, as the steering GMP that re-navigation uses, "
               "and train the default GMP (same sizes) that the other tasks use (give it again on --resume)")
      ->group(sizes);
  cmd.add_option("--window", c.window, "frames per window")->group(sizes);
  cmd.add_option("--stride", o.stride, "frames between training windows");
  cmd.add_option("--frames-per-window", o.frames_per_window, "decoded frames per window and step");
  cmd.add_option("--kl-weight", o.kl_weight, "weight of the KL term after the warm-up");
  cmd.add_option("--kl-warmup", o.kl_warmup, "fraction of the budget over which the KL weight rises from 0");
}

void add_inbetweener_options(CLI::App& cmd, mf::InbetweenTrainingOptions& o, std::vector<std::string>& hp,
                             RunArgs& run) {
  mf::cli::repeatable(cmd.add_option("--hp", hp,
                                     "a model hyperparameter KEY=VALUE (repeatable), e.g. --hp width=128 --hp "
                                     "layers=3 (keys of the kind: width, layers, heads, ffn, window, fps, ...)"));
  cmd.add_option("--config", run.config,
                 "key = value lines: the options without '--'; any other key is a hyperparameter");
  add_run_options(cmd, o, run);
  cmd.add_option("--warmup", o.warmup, "fraction of the budget with a linear learning-rate warm-up");
  cmd.add_option("--min-length", o.min_length, "shortest training window, frames");
  cmd.add_option("--contact-weight", o.contact_weight, "weight of the foot-contact loss");
  cmd.add_option("--checkpoint-minutes", o.checkpoint_minutes, "write last.* at least this often");
  cmd.add_option("--validate-minutes", o.validate_minutes, "an epoch ends after at most this long");
  cmd.add_option("--epoch-steps", o.epoch_steps, "steps per epoch (0 = one pass over the training frames)");
  cmd.add_option("--validation-windows", o.validation_windows, "validation windows (fixed seed)");
  const std::string transitions = "Transitions (keyframe kinds only; training/inbetween_trainer.h)";
  cmd.add_option("--context", o.context, "known frames before the transition")->group(transitions);
  cmd.add_option("--min-transition", o.min_transition, "shortest transition, frames")->group(transitions);
  cmd.add_option("--max-transition", o.max_transition, "longest transition, frames")->group(transitions);
  cmd.footer("Model hyperparameters go in --hp KEY=VALUE.");
}

double number(const std::string& what, const std::string& value) {
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != value.size()) throw mf::InputError(what + ": not a number: '" + value + "'");
  return v;
}

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

// Applies the config file of `cmd` (see the top of this file) after the
// command line was parsed. Keys that name no option of `cmd`, and the values
// of "hp" keys, go to `hyperparameters` as "KEY=VALUE", or are an error when
// it is null.
void apply_config_file(CLI::App& cmd, const std::string& path, std::vector<std::string>* hyperparameters) {
  std::ifstream in(path);
  if (!in) throw mf::InputError(path + ": cannot open the config file");
  std::set<const CLI::Option*> from_command_line;
  for (const CLI::Option* opt : cmd.get_options()) {
    if (opt->count() > 0) from_command_line.insert(opt);
  }
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    line = trim(line.substr(0, line.find('#')));
    if (line.empty()) continue;
    const std::string where = path + ":" + std::to_string(n) + ": ";
    const size_t eq = line.find('=');
    if (eq == std::string::npos) throw mf::InputError(where + "expected key = value");
    const std::string key = trim(line.substr(0, eq)), value = trim(line.substr(eq + 1));
    CLI::Option* opt = key == "config" || key == "hp" ? nullptr : cmd.get_option_no_throw("--" + key);
    if (opt == cmd.get_help_ptr()) opt = nullptr;
    if (opt == nullptr) {
      if (hyperparameters == nullptr) throw mf::InputError(where + "unknown option '" + key + "'");
      hyperparameters->push_back(key == "hp" ? value : key + "=" + value);
      continue;
    }
    if (from_command_line.count(opt)) continue;
    try {
      opt->clear();
      opt->add_result(value);
      opt->run_callback();
    } catch (const CLI::Error& e) {
      throw mf::InputError(where + e.what());
    }
  }
}

// "KEY=VALUE" lists (the config file's first, then the command line's, which
// wins) into a hyperparameter map.
std::map<std::string, double> hyperparameter_map(const std::vector<std::string>& from_config,
                                                 const std::vector<std::string>& from_command_line) {
  std::map<std::string, double> out;
  for (const auto* list : {&from_config, &from_command_line}) {
    for (const std::string& item : *list) {
      const size_t eq = item.find('=');
      if (eq == std::string::npos || eq == 0) throw mf::InputError("--hp: expected KEY=VALUE, got '" + item + "'");
      const std::string key = trim(item.substr(0, eq));
      out[key] = number("--hp " + key, trim(item.substr(eq + 1)));
    }
  }
  return out;
}

int train_prior_main(mf::PriorTrainingOptions o, const RunArgs& run) {
  o.verbose = !run.quiet;
  mf::PriorTrainingResult r = mf::train_prior(o);
  if (o.distributed.rank != 0) return 0;  // rank 0 reports and exports (it alone wrote the output folder)
  std::printf("trained %d epochs, %lld steps in %.1f min; best validation score %.4f: %s\n", r.epochs,
              static_cast<long long>(r.steps), r.minutes, r.best_validation, r.best_path.c_str());
  if (!run.export_path.empty()) {
    mf::save_nemf(mf::load_nemf(r.best_path), run.export_path);
    std::printf("exported %s\n", run.export_path.c_str());
  }
  return 0;
}

int train_inbetweener_main(mf::InbetweenTrainingOptions o, const RunArgs& run) {
  o.verbose = !run.quiet;
  // Fail on bad hyperparameters before loading any data.
  if (!o.resume) {
    mf::RigInfo probe;
    probe.skeleton.names = {"root"};
    probe.skeleton.parents = {-1};
    probe.skeleton.offsets = {Eigen::Vector3d::Zero()};
    mf::make_inbetweener(o.kind, o.hyperparameters, probe);
  }
  mf::InbetweenTrainingResult r = mf::train_inbetweener(o);
  if (o.distributed.rank != 0) return 0;  // rank 0 reports and exports (it alone wrote the output folder)
  std::printf("trained %s: %d epochs, %lld steps in %.1f min (%.2f steps/s this run, %d threads); best validation "
              "loss %.4f: %s\n",
              o.kind.c_str(), r.epochs, static_cast<long long>(r.steps), r.minutes, r.steps_per_second,
              std::max(1, o.threads), r.best_validation, r.best_path.c_str());
  if (!run.export_path.empty()) {
    mf::save_inbetweener(*mf::load_inbetweener(r.best_path), run.export_path);
    std::printf("exported %s\n", run.export_path.c_str());
  }
  return 0;
}

struct RigArgs {
  mf::DatasetOptions data;
  std::string out;
  int stride = 2;
  double locked_sd = 0.6;
};

void add_rig_options(CLI::App& cmd, RigArgs& a) {
  a.data.source = mf::default_train_archive();
  a.data.cache_dir = mf::default_cache_dir();
  cmd.add_option("--out", a.out, "the JSON file to write (models/motionfield-rig.json)")->required();
  cmd.add_option("--data", a.data.source, "folder or .tar/.tar.xz/.tar.gz of BVH files (default: the shared training "
                                          "archive)");
  cmd.add_option("--cache-dir", a.data.cache_dir, "extraction and parse cache (default: <project>/.cache)");
  cmd.add_option("--stride", a.stride, "every N-th frame of the training split")->check(mf::cli::at_least(1));
  cmd.add_option("--locked-sd", a.locked_sd,
                 "a joint's rotation axis counts as locked when its standard deviation over the frames is below this "
                 "many degrees (default 0.6: the knees' and toes' hinges, one axis of the shoulders)")
      ->check(CLI::Range(0.0, 10.0));
}

// motionfield-train rig: the rig anatomy of the training split, as JSON.
int measure_rig_main(const RigArgs& a) {
  const mf::Dataset data = mf::load_dataset(a.data);
  mf::Motion all = mf::Motion::identity(data.skeleton, 0, 30.0);
  for (const mf::Clip& c : data.train) {
    for (int f = 0; f < c.motion.num_frames(); f += a.stride) {
      for (int j = 0; j < c.motion.num_joints(); ++j) all.rotations.push_back(c.motion.rotation(f, j));
      all.root_positions.push_back(c.motion.root_positions[f]);
    }
  }
  mf::RigAnatomy anatomy = mf::estimate_anatomy(all, mf::find_rig_parts(data.skeleton));
  mf::measure_locked_axes(all, a.locked_sd, &anatomy);
  std::ofstream file(a.out);
  file << anatomy.to_json(data.skeleton) << "\n";
  if (!file) throw std::runtime_error("cannot write " + a.out);
  std::printf("measured the rig anatomy on %d frames of %zu training clips: %s\n", all.num_frames(),
              data.train.size(), a.out.c_str());
  for (int j = 0; j < data.skeleton.num_joints(); ++j)
    if (!anatomy.locked_axes[j].empty())
      std::printf("  %s: %zu locked axis(es)\n", data.skeleton.names[j].c_str(), anatomy.locked_axes[j].size());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Trains motionfield's models from a folder or archive of BVH files.", "motionfield-train"};
  mf::cli::use_tool_defaults(app);
  app.require_subcommand(1);
  mf::PriorTrainingOptions prior_options;
  mf::InbetweenTrainingOptions inbetweener_options;
  try {
    prior_options.distributed = inbetweener_options.distributed = mf::DistributedOptions::from_environment();
  } catch (const mf::InputError& e) {
    std::fprintf(stderr, "motionfield-train: %s\n", e.what());
    return 2;
  }
  std::vector<std::string> hp;
  RunArgs run;
  RigArgs rig_args;
  CLI::App* prior = app.add_subcommand("prior", "the NeMF prior (training/prior_trainer.h)");
  add_prior_options(*prior, prior_options, run);
  std::vector<CLI::App*> inbetweeners;  // one subcommand per in-betweener kind
  for (const mf::InbetweenerKind& kind : mf::inbetweener_kinds()) {
    inbetweeners.push_back(
        app.add_subcommand(kind.name, "the " + kind.title + " (" + kind.file_name + "; training/inbetween_trainer.h)"));
    add_inbetweener_options(*inbetweeners.back(), inbetweener_options, hp, run);
  }
  CLI::App* rig = app.add_subcommand("rig", "measures the anatomy of the training data's rig (prior/rig/retarget.h) "
                                            "from the training split: models/motionfield-rig.json");
  add_rig_options(*rig, rig_args);
  return mf::cli::run(app, argc, argv, [&] {
    if (rig->parsed()) return measure_rig_main(rig_args);
    try {
      if (prior->parsed()) {
        if (!run.config.empty()) apply_config_file(*prior, run.config, nullptr);
        return train_prior_main(prior_options, run);
      }
      CLI::App* cmd =
          *std::find_if(inbetweeners.begin(), inbetweeners.end(), [](CLI::App* c) { return c->parsed(); });
      std::vector<std::string> config_hp;
      if (!run.config.empty()) apply_config_file(*cmd, run.config, &config_hp);
      inbetweener_options.kind = cmd->get_name();
      inbetweener_options.hyperparameters = hyperparameter_map(config_hp, hp);
      return train_inbetweener_main(inbetweener_options, run);
    } catch (const mf::training::DistributedError& e) {
      std::fprintf(stderr, "motionfield-train: %s\n", e.what());  // a peer failed: not an internal error
      return 1;
    }
  });
}
