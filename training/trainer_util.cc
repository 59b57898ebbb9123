#include "training/trainer_util.h"

#include <ATen/ATen.h>
#include <torch/optim/adam.h>
#include <torch/optim/optimizer.h>
#include <torch/serialize.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "prior/motion/errors.h"
#include "prior/util/file_writer.h"

namespace mf::training {

Dataset load_training_data(const std::string& source, const std::string& cache_dir, int max_train_clips, double fps,
                           const Augmentation& augmentation, bool verbose) {
  DatasetOptions dopt;
  dopt.source = source;
  dopt.cache_dir = cache_dir;
  dopt.verbose = verbose;
  Dataset data = load_dataset(dopt);
  if (max_train_clips > 0 && static_cast<int>(data.train.size()) > max_train_clips) data.train.resize(max_train_clips);
  if (data.train.empty()) throw InputError("train: no training clips");
  for (const Clip& c : data.train) {
    if (fps > 0 && std::abs(c.motion.fps - fps) > 1e-3) {
      throw InputError("train: clip " + c.name + " is at " + std::to_string(c.motion.fps) + " fps, the model at " +
                       std::to_string(fps) + " fps");
    }
  }
  augment_training_split(data, augmentation, verbose);
  return data;
}

RigInfo measure_training_rig(const Dataset& data) {
  std::vector<const Motion*> motions;
  for (const Clip& c : data.train) motions.push_back(&c.motion);
  return measure_rig(data.skeleton, motions);
}

at::Tensor padded_slice(const at::Tensor& x, int start, int length, int W) {
  at::Tensor s = x.narrow(0, start, length);
  if (length < W) {
    std::vector<int64_t> shape(s.sizes().begin(), s.sizes().end());
    shape[0] = W - length;
    s = at::cat({s, s.narrow(0, length - 1, 1).expand(shape)}, 0);
  }
  return s.unsqueeze(0);
}

at::Tensor masked_mean(const at::Tensor& value, const at::Tensor& mask) {
  at::Tensor v = value.dim() > 2 ? value.flatten(2).mean(-1) : value;
  return (v * mask).sum() / mask.sum().clamp_min(1.0);
}

RunFiles::RunFiles(const std::string& out_dir)
    : last_model(out_dir + "/last.mfm"),
      last_optim(out_dir + "/last.optim"),
      last_state(out_dir + "/last.state"),
      best_model(out_dir + "/best.mfm"),
      log(out_dir + "/log.csv") {}

bool RunFiles::has_checkpoint() const {
  namespace fs = std::filesystem;
  return fs::exists(last_model) && fs::exists(last_state) && fs::exists(last_optim);
}

void save_trainer_state(const std::string& path, const TrainerState& s) {
  std::ostringstream out;
  out.precision(17);
  out << "epoch " << s.epoch << "\nstep " << s.step << "\nminutes " << s.minutes << "\nbest " << s.best << "\nworld_size "
      << s.world_size << "\n";
  const std::string text = out.str();
  write_file_atomically(path, text.data(), text.size());
}

void save_optimizer(const torch::optim::Optimizer& optimizer, const std::string& path) {
  std::ostringstream bytes;
  torch::save(optimizer, bytes);
  const std::string data = bytes.str();
  write_file_atomically(path, data.data(), data.size());
}

TrainerState load_trainer_state(const std::string& path) {
  TrainerState s;
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot read the trainer state");
  std::string key;
  while (in >> key) {
    if (key == "epoch") in >> s.epoch;
    else if (key == "step") in >> s.step;
    else if (key == "minutes") in >> s.minutes;
    else if (key == "best") in >> s.best;
    else if (key == "world_size") in >> s.world_size;
  }
  return s;
}

double scheduled_lr(double lr, double lr_final, double progress, double warmup) {
  progress = std::min(1.0, std::max(0.0, progress));
  if (warmup > 0 && progress < warmup) return lr * std::max(0.01, progress / warmup);
  const double p = warmup > 0 ? (progress - warmup) / (1.0 - warmup) : progress;
  return lr_final + 0.5 * (lr - lr_final) * (1.0 + std::cos(M_PI * p));
}

void set_learning_rate(torch::optim::Optimizer& optimizer, double lr) {
  for (auto& group : optimizer.param_groups()) static_cast<torch::optim::AdamOptions&>(group.options()).lr(lr);
}

}  // namespace mf::training
