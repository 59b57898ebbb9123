// libtorch's compute threads (training, the benchmarks and tests that run the
// libtorch networks) and the BLAS under them (prior/util/blas.h).
// libtorch's at::set_num_threads sizes its own intra-op pool only; OpenBLAS
// keeps a pool of its own, so a "1 thread" run would still multiply matrices
// on every core, and a 2-thread run nests two pools that thrash.
// set_compute_threads sizes libtorch's pool and keeps OpenBLAS's at 1.
#pragma once

#include "prior/util/blas.h"

namespace mf {

/// at::set_num_threads(n) and keep_blas_single_threaded(). n >= 1.
void set_compute_threads(int n);

/// Limits the calling thread's intra-op parallelism (libtorch's and our own
/// at::parallel_for loops) to `n` threads until destroyed, then restores it;
/// other threads keep theirs. n <= 0 changes nothing. In builds without OpenMP
/// (clang: sanitizers, fuzzing) it changes nothing either.
class ScopedComputeThreads {
 public:
  explicit ScopedComputeThreads(int n);
  ~ScopedComputeThreads();
  ScopedComputeThreads(const ScopedComputeThreads&) = delete;
  ScopedComputeThreads& operator=(const ScopedComputeThreads&) = delete;

 private:
  int saved_ = 0;  // 0: nothing to restore
};

}  // namespace mf
