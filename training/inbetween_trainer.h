// Training of the learned in-betweeners (prior/inbetween/inbetweener.h, kinds
// "twostage" and "citl") on the same data and split as the prior, with a time
// budget, checkpoints, resume and CSV logs.
//
// Samples: a training clip drawn with probability proportional to its length,
// a window length L uniform in [min_length, window] (a clip shorter than L
// gives its own length; the rest of the batch tensor is padding, valid = 0),
// a uniform start, canonical at the window's first frame. Known pattern per
// sample (frame 0 and the last valid frame are always fully known):
//   50% gap      context of c in [1, 10] frames from frame 0, then a gap to the
//                last frame (the LaFAN1 protocol: 10 context + T + 1 target)
//   40% sparse   keys at random spacings (uniform 2..40 frames) or a random
//                subset of frames (probability 2-30% each)
//   10% partial  like sparse, then about half of the interior keys give only
//                the root, only the legs or a random subset of joints, and
//                their root position with probability 1/2
// Kinds that predict keyframes (kKeyframeKind, prior/inbetween/keyframe_net.h)
// train on transitions instead: `context` known frames from frame 0, a
// transition uniform in [min_transition, max_transition] frames, then the
// target frame (a clip shorter than that gives its own length with the context
// cut to leave at least one unknown frame); the trajectory of every frame is
// the ground truth's (InbetweenBatch::trajectory), the keyframe score targets
// are the Salient Poses scores of the transition (last context frame .. target;
// training/salient_poses.h, with the model's min_spacing), and the loss is
// training/keyframe_losses.h's (the per-stage columns of the log hold
// KeyframeNet's and RefineNet's weighted totals; the validation score is
// RefineNet's).
// Loss (other kinds): the sum over stages of inbetween_pose_loss on every valid frame, plus
// contact_weight * BCE(contact logits, gmp_targets(...).contacts) when the
// model predicts contacts.
//
// Schedule: Adam, linear warm-up over the first `warmup` fraction of the
// budget, then cosine decay to lr_final at the end of the budget (progress is
// the larger of the time fraction and, with max_steps, the step fraction).
// Validation: `validation_windows` windows of the validation clips sampled as
// above with a fixed seed (the same every epoch and run); the score is the
// last stage's inbetween_pose_loss and chooses best.mfm. An "epoch" is
// `epoch_steps` steps (0 = about one pass over the training frames) or
// `validate_minutes` of wall time, whichever comes first.
//
// Data-parallel (options.distributed.world_size = N > 1, training/data_parallel.h):
// every process draws the step's N * batch samples from the same seed and
// trains on its own `batch` of them; the gradients are averaged weighted by
// valid frames, so N processes take the steps of one process with batch
// N * batch. An epoch of about one pass has N times fewer steps.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "training/augmentation.h"
#include "training/data_parallel.h"

namespace mf {

struct InbetweenTrainingOptions {
  std::string kind;                 ///< kTwoStageKind, kCitlKind (or a registered kind)
  std::map<std::string, double> hyperparameters;  ///< the kind's; missing ones take its defaults
  std::string data;                 ///< archive or folder of BVH files
  std::string cache_dir;
  std::string out_dir;              ///< checkpoints, log.csv; created if missing
  uint64_t seed = 1;
  int threads = 1;
  double max_minutes = 60.0;        ///< wall-time budget, including previous runs when resuming
  int max_epochs = 1000000;
  int max_steps = 0;                ///< 0 = unlimited
  int batch = 32;
  int min_length = 12;              ///< shortest training window, frames
  double lr = 5e-4;
  double lr_final = 1e-5;
  double warmup = 0.03;             ///< fraction of the budget
  double contact_weight = 0.5;
  int context = 10;                 ///< keyframe kinds: known frames before the transition
  int min_transition = 5;           ///< keyframe kinds: shortest transition, frames
  int max_transition = 90;          ///< keyframe kinds: longest transition, frames
  double checkpoint_minutes = 5.0;  ///< last.* written at least this often
  double validate_minutes = 6.0;    ///< an epoch ends after at most this long
  int epoch_steps = 0;              ///< 0 = about one pass over the training frames
  int validation_windows = 256;
  bool resume = false;              ///< continue from out_dir/last.* when present
  /// Start a new run from this model's weights and pose statistics instead of
  /// random weights (fine-tuning, or continuing a finished run with a new
  /// schedule): the same kind, the hyperparameters given must match it, and its
  /// skeleton must be the data's. Ignored when resuming.
  std::string init_from;
  int max_train_clips = 0;          ///< 0 = all
  /// Clips added to the training split (training/augmentation.h); give the
  /// same again on --resume.
  training::Augmentation augmentation;
  bool verbose = true;
  /// Data-parallel training (training/data_parallel.h): `batch` samples per
  /// process and step, a global batch of world_size * batch.
  DistributedOptions distributed;
};

struct InbetweenTrainingResult {
  int epochs = 0;
  int64_t steps = 0;
  double minutes = 0.0;
  double steps_per_second = 0.0;    ///< of this run
  double best_validation = 0.0;     ///< last-stage validation loss of best.mfm
  std::string best_path;            ///< out_dir/best.mfm
};

/// Trains and writes out_dir/{best.mfm,last.mfm,last.optim,last.state,log.csv}.
/// Throws InputError for bad options or data (including --resume with another
/// kind or other hyperparameters than the checkpoint).
InbetweenTrainingResult train_inbetweener(const InbetweenTrainingOptions& options);

}  // namespace mf
