// Pieces shared by the training programs (prior_trainer.cc,
// inbetween_trainer.cc): data loading with the common checks, padding, the
// trainer state file, learning-rate schedule.
#pragma once

#include <ATen/core/Tensor.h>
#include <cstdint>
#include <string>
#include <vector>

#include "prior/data/dataset.h"
#include "prior/model/representation.h"
#include "training/augmentation.h"

namespace torch::optim {
class Optimizer;
}

namespace mf::training {

/// Loads `data` (folder or archive) through the cache, keeps at most
/// `max_train_clips` training clips (0 = all), checks that every training
/// clip is at `fps` (when fps > 0), then adds `augmentation`'s clips to the
/// training split (augmentation.h; the validation split is never augmented).
/// Throws InputError when there is no training clip and for the errors of
/// augment_training_split.
Dataset load_training_data(const std::string& data, const std::string& cache_dir, int max_train_clips, double fps,
                           const Augmentation& augmentation, bool verbose);

/// The rig measured from the training clips (as the prior's trainer does).
RigInfo measure_training_rig(const Dataset& data);

/// Frames [start, start + length) of x [T, ...] padded to W by repeating the
/// last frame, with a leading batch dimension: [1, W, ...].
at::Tensor padded_slice(const at::Tensor& x, int start, int length, int W);

/// Mean over the trailing dimensions of value [B, S, ...], then over the
/// frames where mask [B, S] is 1.
at::Tensor masked_mean(const at::Tensor& value, const at::Tensor& mask);

/// The files a run writes in its output folder.
struct RunFiles {
  explicit RunFiles(const std::string& out_dir);
  std::string last_model;  ///< out_dir/last.mfm
  std::string last_optim;  ///< out_dir/last.optim
  std::string last_state;  ///< out_dir/last.state
  std::string best_model;  ///< out_dir/best.mfm
  std::string log;         ///< out_dir/log.csv
  /// True when an earlier run left a checkpoint to resume from (last.*).
  bool has_checkpoint() const;
};

/// What a run needs to resume besides the model and optimiser (out_dir/last.state).
struct TrainerState {
  int epoch = 0;
  int64_t step = 0;
  double minutes = 0.0;  ///< wall time of all runs so far
  double best = 1e30;    ///< best validation score
  int world_size = 1;    ///< processes of the data-parallel run (training/data_parallel.h); 1 in older files
};
void save_trainer_state(const std::string& path, const TrainerState& s);
/// Saves an optimiser's state (torch::save) through the one file writer
/// (prior/util/file_writer.h).
void save_optimizer(const torch::optim::Optimizer& optimizer, const std::string& path);
TrainerState load_trainer_state(const std::string& path);

/// Cosine decay from lr to lr_final as progress goes 0 -> 1, after a linear
/// warm-up over the first `warmup` fraction of progress (0 = none).
double scheduled_lr(double lr, double lr_final, double progress, double warmup = 0.0);
void set_learning_rate(torch::optim::Optimizer& optimizer, double lr);

}  // namespace mf::training
