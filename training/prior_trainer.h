// Training of the NeMF-style prior (prior/model/nemf.h) on a folder or archive
// of BVH clips, with a time budget, checkpoints, resume and CSV logs.
//
// Data: every training clip is cut into windows of `config.window` frames at a
// stride of `stride` frames with a random phase per epoch; clips shorter than a
// window give one window of their own length (padded and masked, see nemf.h).
// Each window is made canonical at its first frame.
//
// Losses (NeMF's): geodesic(local rotations) + geodesic(root orientation)
// + 10 * L1(FK positions relative to the root) + beta * KL, beta warmed up
// linearly from 0 to `kl_weight` over the first `kl_warmup` fraction of the
// budget; the decoder is trained on `frames_per_window` random frames of each
// window (it is a field over time). The GMP is trained on ground-truth local
// motion: L1(velocity) + L1(height) + L1(translation) + 0.5 * BCE(contacts).
// Validation (encode the mean, decode every frame) after each epoch chooses
// the best checkpoint (with gmp_only: the GMP's translation error). With options.distributed.world_size > 1 the processes
// share each step's global batch (training/data_parallel.h); N processes with
// batch B take the steps of one process with batch N * B (exactly so when the
// windows of a step are all full length; a last global batch of fewer
// windows than processes is skipped).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "prior/model/nemf.h"
#include "training/augmentation.h"
#include "training/data_parallel.h"

namespace mf {

struct PriorTrainingOptions {
  std::string data;                 ///< archive or folder of BVH files
  std::string cache_dir;            ///< extraction / parse cache
  std::string out_dir;              ///< checkpoints, log.csv; created if missing
  NemfConfig config;
  uint64_t seed = 1;
  int threads = 2;
  double max_minutes = 60.0;        ///< wall-time budget of this run, including previous runs when resuming
  int max_epochs = 1000000;
  int batch = 32;
  int stride = 32;
  int frames_per_window = 32;
  double lr = 1e-3;
  double lr_final = 1e-5;           ///< cosine decay over the budget down to this
  double kl_weight = 1e-5;
  double kl_warmup = 0.2;
  bool resume = false;              ///< continue from out_dir/last.* when present
  /// Start a new run from this prior's weights and normalisation statistics
  /// instead of random weights (fine-tuning, or continuing a finished run with
  /// a new schedule). Its sizes must equal `config` and its skeleton the data's
  /// (Skeleton::same_as, as the in-betweener trainer checks); its rig and
  /// statistics are kept. Ignored when resuming.
  std::string init_from;
  /// Train only the global motion predictor, of `config`'s GMP sizes, on
  /// --init's VAE: the VAE's weights and every statistic are --init's and stay
  /// frozen, its other sizes must equal `config`'s, and the best checkpoint is
  /// the one with the lowest validation translation error (the VAE's
  /// validation figures are logged but constant). --init's GMP is kept when
  /// its sizes are `config`'s, else a fresh one is trained. For a smaller,
  /// faster GMP without retraining the VAE. Give it again on --resume.
  /// With config.steering_gmp, --init's GMP (or its steering GMP if it has
  /// one) is kept, frozen, as the model's steering GMP and the default GMP is
  /// the one trained; the GMP sizes must then be --init's.
  bool gmp_only = false;
  /// With gmp_only: the share of each batch's windows (and of the validation
  /// windows) whose GMP inputs come from the frozen VAE's reconstruction
  /// (encode the mean, decode every frame) instead of the captured motion;
  /// the targets stay the captured motion's. In a task the GMP reads decoded
  /// motion, not captured motion. Give it again on --resume.
  double gmp_reconstructed = 0.0;
  int max_train_clips = 0;          ///< 0 = all (small values for smoke tests)
  /// Clips added to the training split (training/augmentation.h); give the
  /// same again on --resume.
  training::Augmentation augmentation;
  int max_steps = 0;                ///< 0 = unlimited (for tests)
  bool verbose = true;
  /// Data-parallel training (training/data_parallel.h): `batch` windows per
  /// process and step, a global batch of world_size * batch.
  DistributedOptions distributed;
};

struct PriorTrainingResult {
  int epochs = 0;
  int64_t steps = 0;
  double minutes = 0.0;
  double best_validation = 0.0;     ///< rotation + position validation loss of the best checkpoint
  std::string best_path;            ///< out_dir/best.mfm
};

/// Trains and writes out_dir/{best.mfm,last.mfm,last.state,last.optim,log.csv}.
/// Throws InputError for bad options or data.
PriorTrainingResult train_prior(const PriorTrainingOptions& options);

}  // namespace mf
