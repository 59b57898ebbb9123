// motionfield-train: trains motionfield's models from a folder or archive of BVH files.
//
//   motionfield-train prior --out DIR [--data PATH] [--config FILE] [--width N] [--layers N]
//                           [--zl N] [--zg N] [--max-minutes M] [--seed S] [--threads N] [--resume] ...
//   motionfield-train twostage|citl --out DIR [--data PATH] [--hp key=value]... [--config FILE]
//                           [--max-minutes M] [--seed S] [--threads N] [--resume] [--export PATH] ...
//
// Exit codes: 0 ok, 2 bad input, 1 internal error.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>

#include "prior/data/dataset.h"
#include "prior/inbetween/inbetweener.h"
#include "prior/model/model_file.h"
#include "prior/motion/errors.h"
#include "prior/rig/retarget.h"
#include "training/inbetween_trainer.h"
#include "training/prior_trainer.h"

namespace {

const char* kUsage =
    "usage: motionfield-train prior --out DIR [options]\n"
    "       motionfield-train twostage --out DIR [in-betweener options]\n"
    "       motionfield-train citl --out DIR [in-betweener options]\n"
    "       motionfield-train rig --out FILE.json [--data PATH] [--cache-dir DIR] [--stride N]\n"
    "                 measures the anatomy of the training data's rig (prior/rig/retarget.h) from the\n"
    "                 training split, every N-th frame (default 2): models/motionfield-rig.json\n"
    "\n"
    "prior options:\n"
    "  --data PATH          folder or .tar/.tar.xz/.tar.gz of BVH files (default: the shared training archive)\n"
    "  --cache-dir DIR      extraction and parse cache (default: <project>/.cache)\n"
    "  --config FILE        key = value lines, same keys as the flags below without '--'\n"
    "  --width N --layers N --zl N --zg N --zg-layers N --encoder-channels N --pe N\n"
    "  --gmp-width N --gmp-kernel N --gmp-blocks N --window N\n"
    "  --max-minutes M      wall-time budget, counting earlier runs when resuming (default 60)\n"
    "  --max-epochs N --batch N --stride N --frames-per-window N --lr X --lr-final X\n"
    "  --kl-weight X --kl-warmup X --seed N --threads N (default 2) --max-train-clips N --max-steps N\n"
    "  --resume             continue from DIR/last.* if present\n"
    "  --export PATH        copy the best checkpoint to PATH at the end\n"
    "  --quiet\n"
    "\n"
    "in-betweener options (twostage: context + detail transformers; citl):\n"
    "  --data PATH --cache-dir DIR   as for the prior (same data, same split)\n"
    "  --hp KEY=VALUE       a model hyperparameter (repeatable), e.g. --hp width=128 --hp layers=3\n"
    "                       (keys of the kind: width, layers, heads, ffn, window, fps, ...)\n"
    "  --config FILE        key = value lines: the options below without '--'; any other key is a\n"
    "                       hyperparameter\n"
    "  --max-minutes M      wall-time budget, counting earlier runs when resuming (default 60)\n"
    "  --max-epochs N --max-steps N --batch N (32) --lr X (5e-4) --lr-final X (1e-5) --warmup F (0.03)\n"
    "  --min-length N (12) --contact-weight X (0.5) --checkpoint-minutes M (5) --validate-minutes M (6)\n"
    "  --epoch-steps N (0 = one pass over the training frames) --validation-windows N (256)\n"
    "  --seed N --threads N (default 1) --max-train-clips N\n"
    "  --resume             continue from DIR/last.* if present\n"
    "  --export PATH        copy the best checkpoint to PATH at the end\n"
    "  --quiet\n"
    "\n"
    "Exit codes: 0 ok, 2 bad input, 1 internal error.\n";

double number(const std::string& key, const std::string& value) {
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != value.size()) throw mf::InputError("--" + key + ": not a number: '" + value + "'");
  return v;
}

void apply(mf::PriorTrainingOptions& o, std::string& export_path, const std::string& key, const std::string& value) {
  auto i = [&] { return static_cast<int>(number(key, value)); };
  auto d = [&] { return number(key, value); };
  if (key == "data") o.data = value;
  else if (key == "cache-dir") o.cache_dir = value;
  else if (key == "out") o.out_dir = value;
  else if (key == "width") o.config.decoder_width = i();
  else if (key == "layers") o.config.decoder_layers = i();
  else if (key == "zl") o.config.zl = i();
  else if (key == "zg") o.config.zg = i();
  else if (key == "zg-layers") o.config.zg_layers = i();
  else if (key == "encoder-channels") o.config.encoder_channels = i();
  else if (key == "pe") o.config.pe_frequencies = i();
  else if (key == "gmp-width") o.config.gmp_width = i();
  else if (key == "gmp-kernel") o.config.gmp_kernel = i();
  else if (key == "gmp-blocks") o.config.gmp_blocks = i();
  else if (key == "window") o.config.window = i();
  else if (key == "max-minutes") o.max_minutes = d();
  else if (key == "max-epochs") o.max_epochs = i();
  else if (key == "batch") o.batch = i();
  else if (key == "stride") o.stride = i();
  else if (key == "frames-per-window") o.frames_per_window = i();
  else if (key == "lr") o.lr = d();
  else if (key == "lr-final") o.lr_final = d();
  else if (key == "kl-weight") o.kl_weight = d();
  else if (key == "kl-warmup") o.kl_warmup = d();
  else if (key == "seed") o.seed = static_cast<uint64_t>(d());
  else if (key == "threads") o.threads = i();
  else if (key == "max-train-clips") o.max_train_clips = i();
  else if (key == "max-steps") o.max_steps = i();
  else if (key == "export") export_path = value;
  else throw mf::InputError("unknown option --" + key);
}

void apply(mf::InbetweenTrainingOptions& o, std::string& export_path, const std::string& key,
           const std::string& value);

template <class Options>
void read_config(Options& o, std::string& export_path, const std::string& path) {
  std::ifstream in(path);
  if (!in) throw mf::InputError(path + ": cannot open the config file");
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    size_t eq = line.find('=');
    auto trim = [](std::string s) {
      size_t a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
      return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
    };
    if (trim(line).empty()) continue;
    if (eq == std::string::npos) throw mf::InputError(path + ":" + std::to_string(n) + ": expected key = value");
    apply(o, export_path, trim(line.substr(0, eq)), trim(line.substr(eq + 1)));
  }
}

void apply(mf::InbetweenTrainingOptions& o, std::string& export_path, const std::string& key,
           const std::string& value) {
  auto i = [&] { return static_cast<int>(number(key, value)); };
  auto d = [&] { return number(key, value); };
  if (key == "data") o.data = value;
  else if (key == "cache-dir") o.cache_dir = value;
  else if (key == "out") o.out_dir = value;
  else if (key == "max-minutes") o.max_minutes = d();
  else if (key == "max-epochs") o.max_epochs = i();
  else if (key == "max-steps") o.max_steps = i();
  else if (key == "batch") o.batch = i();
  else if (key == "lr") o.lr = d();
  else if (key == "lr-final") o.lr_final = d();
  else if (key == "warmup") o.warmup = d();
  else if (key == "min-length") o.min_length = i();
  else if (key == "contact-weight") o.contact_weight = d();
  else if (key == "checkpoint-minutes") o.checkpoint_minutes = d();
  else if (key == "validate-minutes") o.validate_minutes = d();
  else if (key == "epoch-steps") o.epoch_steps = i();
  else if (key == "validation-windows") o.validation_windows = i();
  else if (key == "seed") o.seed = static_cast<uint64_t>(d());
  else if (key == "threads") o.threads = i();
  else if (key == "max-train-clips") o.max_train_clips = i();
  else if (key == "export") export_path = value;
  else if (key == "hp") {
    size_t eq = value.find('=');
    if (eq == std::string::npos || eq == 0) throw mf::InputError("--hp: expected KEY=VALUE, got '" + value + "'");
    std::string k = value.substr(0, eq);
    o.hyperparameters[k] = number("hp " + k, value.substr(eq + 1));
  } else {
    o.hyperparameters[key] = number(key, value);  // config files: any other key is a hyperparameter
  }
}

int train_inbetweener_main(const std::string& kind, int argc, char** argv) {
  mf::InbetweenTrainingOptions o;
  o.kind = kind;
  o.data = mf::default_train_archive();
  o.cache_dir = mf::default_cache_dir();
  std::string export_path;
  for (int i = 2; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--resume") o.resume = true;
    else if (a == "--quiet") o.verbose = false;
    else if (a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a.rfind("--", 0) == 0 && i + 1 < argc) {
      std::string key = a.substr(2), value = argv[++i];
      if (key == "config") read_config(o, export_path, value);
      else {
        // Flags on the command line must be known options or --hp.
        static const char* known[] = {"data", "cache-dir", "out", "max-minutes", "max-epochs", "max-steps", "batch",
                                      "lr", "lr-final", "warmup", "min-length", "contact-weight",
                                      "checkpoint-minutes", "validate-minutes", "epoch-steps",
                                      "validation-windows", "seed", "threads", "max-train-clips", "export", "hp"};
        bool ok = false;
        for (const char* k : known) ok = ok || key == k;
        if (!ok) throw mf::InputError("unknown option --" + key + " (model hyperparameters go in --hp KEY=VALUE)");
        apply(o, export_path, key, value);
      }
    } else {
      throw mf::InputError("unexpected argument '" + a + "' (options take a value)");
    }
  }
  // Fail on bad hyperparameters before loading any data.
  if (!o.resume) {
    mf::RigInfo probe;
    probe.skeleton.names = {"root"};
    probe.skeleton.parents = {-1};
    probe.skeleton.offsets = {Eigen::Vector3d::Zero()};
    mf::make_inbetweener(o.kind, o.hyperparameters, probe);
  }
  mf::InbetweenTrainingResult r = mf::train_inbetweener(o);
  std::printf("trained %s: %d epochs, %lld steps in %.1f min (%.2f steps/s this run, %d threads); best validation "
              "loss %.4f: %s\n",
              kind.c_str(), r.epochs, static_cast<long long>(r.steps), r.minutes, r.steps_per_second,
              std::max(1, o.threads), r.best_validation, r.best_path.c_str());
  if (!export_path.empty()) {
    mf::save_inbetweener(*mf::load_inbetweener(r.best_path), export_path);
    std::printf("exported %s\n", export_path.c_str());
  }
  return 0;
}

}  // namespace

// motionfield-train rig: the rig anatomy of the training split, as JSON.
int measure_rig_main(int argc, char** argv) {
  mf::DatasetOptions d;
  d.source = mf::default_train_archive();
  d.cache_dir = mf::default_cache_dir();
  std::string out;
  int stride = 2;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--", 0) != 0 || i + 1 >= argc) throw mf::InputError("unexpected argument '" + a + "'");
    const std::string key = a.substr(2), value = argv[++i];
    if (key == "out") out = value;
    else if (key == "data") d.source = value;
    else if (key == "cache-dir") d.cache_dir = value;
    else if (key == "stride") stride = static_cast<int>(number(key, value));
    else throw mf::InputError("unknown option --" + key + " for rig");
  }
  if (out.empty()) throw mf::InputError("rig: --out FILE is required");
  if (stride < 1) throw mf::InputError("rig: --stride must be at least 1");
  const mf::Dataset data = mf::load_dataset(d);
  mf::Motion all = mf::Motion::identity(data.skeleton, 0, 30.0);
  for (const mf::Clip& c : data.train) {
    for (int f = 0; f < c.motion.num_frames(); f += stride) {
      for (int j = 0; j < c.motion.num_joints(); ++j) all.rotations.push_back(c.motion.rotation(f, j));
      all.root_positions.push_back(c.motion.root_positions[f]);
    }
  }
  const mf::RigAnatomy a = mf::estimate_anatomy(all, mf::find_rig_parts(data.skeleton));
  std::ofstream file(out);
  file << a.to_json(data.skeleton) << "\n";
  if (!file) throw std::runtime_error("cannot write " + out);
  std::printf("measured the rig anatomy on %d frames of %zu training clips: %s\n", all.num_frames(),
              data.train.size(), out.c_str());
  return 0;
}

int main(int argc, char** argv) {
  try {
    if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
      std::fputs(kUsage, argc < 2 ? stderr : stdout);
      return argc < 2 ? 2 : 0;
    }
    const std::string kind = argv[1];
    if (kind == "rig") return measure_rig_main(argc, argv);
    if (kind == mf::kTwoStageKind || kind == mf::kCitlKind) return train_inbetweener_main(kind, argc, argv);
    if (kind != "prior") {
      throw mf::InputError("unknown model kind '" + kind + "' (expected prior, twostage or citl)");
    }
    mf::PriorTrainingOptions o;
    o.data = mf::default_train_archive();
    o.cache_dir = mf::default_cache_dir();
    std::string export_path;
    for (int i = 2; i < argc; ++i) {
      std::string a = argv[i];
      if (a == "--resume") o.resume = true;
      else if (a == "--quiet") o.verbose = false;
      else if (a == "--help") {
        std::fputs(kUsage, stdout);
        return 0;
      } else if (a.rfind("--", 0) == 0 && i + 1 < argc) {
        std::string key = a.substr(2), value = argv[++i];
        if (key == "config") read_config(o, export_path, value);
        else apply(o, export_path, key, value);
      } else {
        throw mf::InputError("unexpected argument '" + a + "' (options take a value)");
      }
    }
    mf::PriorTrainingResult r = mf::train_prior(o);
    std::printf("trained %d epochs, %lld steps in %.1f min; best validation score %.4f: %s\n", r.epochs,
                static_cast<long long>(r.steps), r.minutes, r.best_validation, r.best_path.c_str());
    if (!export_path.empty()) {
      mf::save_nemf(mf::load_nemf(r.best_path), export_path);
      std::printf("exported %s\n", export_path.c_str());
    }
    return 0;
  } catch (const mf::InputError& e) {
    std::fprintf(stderr, "motionfield-train: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "motionfield-train: internal error: %s\n", e.what());
    return 1;
  }
}
