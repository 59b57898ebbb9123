#include "training/trainer_util.h"

#include <ATen/ATen.h>
#include <torch/optim/adam.h>
#include <torch/optim/optimizer.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "prior/motion/errors.h"
#include "prior/motion/interpolation.h"
#include "prior/motion/rotations.h"
#include "prior/rig/mirror.h"

namespace mf::training {

Motion played_at_speed(const Motion& motion, double speed) {
  if (!(std::isfinite(speed) && speed > 0)) throw InputError("a playback speed must be finite and positive");
  Motion faster = motion;
  faster.fps = motion.fps * speed;  // resampled back to the motion's rate: frame i lands at position i * speed
  const int frames = static_cast<int>(std::floor((motion.num_frames() - 1) / speed + 1e-9)) + 1;
  return resample_cubic(faster, motion.fps, frames);
}

Dataset load_training_data(const std::string& source, const std::string& cache_dir, int max_train_clips, double fps,
                           bool mirror, const std::vector<double>& speeds, bool verbose) {
  for (double s : speeds)
    if (!(s >= 0.5 && s <= 2.0) || std::abs(s - 1.0) < 1e-6)
      throw InputError("train: --speeds takes playback speeds in [0.5, 2] other than 1, got " + std::to_string(s));
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
  if (mirror) {
    data.train.reserve(2 * data.train.size());  // the pointers below stay valid while the mirrors are added
    std::vector<const Motion*> motions;
    for (const Clip& c : data.train) motions.push_back(&c.motion);
    const MirrorMap map = mirror_map(data.skeleton, mean_local_rotations(motions));
    const size_t n = data.train.size();
    for (size_t i = 0; i < n; ++i)
      data.train.push_back({data.train[i].name + "#mirror", mirror_motion(data.train[i].motion, map)});
    if (verbose) {
      // The twists are chosen to keep the mean local rotations; how close they stay says whether they were found.
      std::vector<const Motion*> mirrored;
      for (size_t i = n; i < data.train.size(); ++i) mirrored.push_back(&data.train[i].motion);
      const std::vector<Eigen::Quaterniond> a = mean_local_rotations(motions), b = mean_local_rotations(mirrored);
      double worst = 0.0;
      size_t at = 0;
      for (size_t j = 1; j < a.size(); ++j) {
        const double d = geodesic_angle(a[j], b[j]) * 180.0 / M_PI;
        if (d > worst) worst = d, at = j;
      }
      std::fprintf(stderr,
                   "train: %zu mirrored clips added (rest offsets mirror within %.2f cm; mean local rotations "
                   "within %.1f deg of the originals', the most at %s)\n",
                   n, map.max_asymmetry * 100.0, worst, data.skeleton.names[at].c_str());
    }
  }
  if (!speeds.empty()) {
    const size_t n = data.train.size();
    data.train.reserve(n * (1 + speeds.size()));
    for (double s : speeds)
      for (size_t i = 0; i < n; ++i) {
        char name[32];
        std::snprintf(name, sizeof name, "@%gx", s);
        data.train.push_back({data.train[i].name + name, played_at_speed(data.train[i].motion, s)});
      }
    if (verbose) std::fprintf(stderr, "train: %zu clips played at other speeds added\n", n * speeds.size());
  }
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
  {
    std::ofstream out(path + ".tmp");
    out.precision(17);
    out << "epoch " << s.epoch << "\nstep " << s.step << "\nminutes " << s.minutes << "\nbest " << s.best << "\nworld_size "
        << s.world_size << "\n";
  }
  std::filesystem::rename(path + ".tmp", path);
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
