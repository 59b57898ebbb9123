// Data-parallel training over several processes (on one or several hosts),
// shared by every trainer (prior_trainer.cc, inbetween_trainer.cc): libtorch's
// c10d ProcessGroupGloo over TCP, with a TCPStore on the master for the
// rendezvous (the same scheme and environment variables as torchrun).
//
// Every process (a "rank") loads the whole training data and draws the same
// global batch of `world_size * batch` samples with the same seeds; shard()
// gives each rank its own contiguous part. After the backward pass,
// average_gradients() all-reduces the gradients weighted by each rank's share
// of the global batch, so every rank takes the same optimiser step as one
// process on the whole global batch would, and the replicas stay identical.
// Rank 0 alone writes checkpoints and logs (writes()); the others read the
// checkpoint to resume from through rank 0 (resume_files()), so the output
// folder need not be shared between hosts. Wall-time decisions (budget, epoch
// end, checkpoint time) are rank 0's (agree()).
//
// With world_size 1 (the default) no process group is made and every call is
// the identity: the single-process trainers behave exactly as before.
#pragma once

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "training/trainer_util.h"

namespace mf {

/// Where a process sits in a data-parallel run (motionfield-train --world-size,
/// --rank, --master, --dist-timeout; README "Training on several processes or hosts").
struct DistributedOptions {
  int world_size = 1;                 ///< number of processes; 1 = not distributed
  int rank = 0;                       ///< this process, in [0, world_size)
  std::string master_addr = "127.0.0.1";  ///< host of rank 0 (its TCPStore)
  int master_port = 29500;            ///< TCP port of the TCPStore on rank 0
  double timeout_seconds = 180.0;     ///< rendezvous and every collective; a dead peer ends the run after this long

  /// Defaults from torchrun's environment variables WORLD_SIZE, RANK,
  /// MASTER_ADDR and MASTER_PORT where set (InputError when malformed).
  static DistributedOptions from_environment();
  /// Parses "ADDR:PORT" (the last ':' separates the port) into master_addr and
  /// master_port; InputError when malformed.
  void set_master(const std::string& address);
  /// Empty when valid, else what is wrong.
  std::string validate() const;
};

namespace training {

/// A collective operation failed or timed out: a peer died, hung or is
/// unreachable. The message names the operation, this rank and the timeout.
class DistributedError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The process group of one run (see the top of this file).
class DataParallel {
 public:
  /// Joins the group (rank 0 starts the TCPStore on master_port and waits
  /// for the others); world_size 1 joins nothing. Throws InputError for bad
  /// options and DistributedError when the group does not form within the timeout.
  explicit DataParallel(const DistributedOptions& options);
  ~DataParallel();
  DataParallel(const DataParallel&) = delete;
  DataParallel& operator=(const DataParallel&) = delete;

  int rank() const { return options_.rank; }
  int world_size() const { return options_.world_size; }
  bool distributed() const { return options_.world_size > 1; }
  /// True on the rank that writes checkpoints, logs and progress lines (rank 0).
  bool writes() const { return options_.rank == 0; }
  /// "rank R of N" (empty when not distributed), for log lines.
  std::string describe() const;

  /// This rank's part [first, second) of the global batch [begin, end):
  /// contiguous, the sizes differ by at most one, in rank order.
  std::pair<size_t, size_t> shard(size_t begin, size_t end) const;
  /// Whether item `index` of a list dealt round-robin (validation batches) is this rank's.
  bool owns(size_t index) const { return index % static_cast<size_t>(world_size()) == static_cast<size_t>(rank()); }

  /// Copies rank 0's values of `tensors` into every rank's (in place).
  void broadcast(const std::vector<at::Tensor>& tensors);
  /// Replaces each parameter's gradient by the sum over ranks of
  /// grad * local_weight / global_weight, where global_weight is the sum of
  /// the ranks' local weights (the share of the global batch: samples or
  /// frames). Undefined gradients count as zero.
  void average_gradients(const std::vector<at::Tensor>& parameters, double local_weight);
  /// The element-wise sum over ranks.
  std::vector<double> sum(const std::vector<double>& values);
  /// Rank 0's `values` on every rank (wall-time decisions).
  std::vector<double> agree(const std::vector<double>& values);

  /// The checkpoint files a rank resumes from: rank 0's own `files`; on the
  /// other ranks copies of rank 0's last.mfm, last.optim and last.state in a
  /// private temporary folder. Sets *resuming to rank 0's decision
  /// (`want_resume` and rank 0 has a checkpoint).
  RunFiles resume_files(const RunFiles& files, bool want_resume, bool* resuming);
  /// InputError unless the checkpoint's world size is this run's.
  void check_resumed_world_size(const TrainerState& state) const;

 private:
  struct Group;
  at::Tensor run(const char* what, std::vector<at::Tensor> tensors, bool broadcast);
  std::vector<uint8_t> broadcast_bytes(const char* what, std::vector<uint8_t> bytes);

  DistributedOptions options_;
  std::unique_ptr<Group> group_;
  std::string scratch_;  // temporary folder of resume_files() on ranks > 0
  at::Tensor gradient_buffer_;  // average_gradients()' all-reduce buffer, reused
};

}  // namespace training
}  // namespace mf
