#include "prior/util/threads.h"

#include <ATen/Parallel.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include <algorithm>

namespace mf {

void set_compute_threads(int n) {
  at::set_num_threads(std::max(1, n));
  // OpenBLAS's own pool stays at 1: libtorch calls BLAS from inside its
  // intra-op threads, and a second pool under them thrashes (a 40-iteration
  // sparse solve: 2.3-2.5 s with both pools at 2, 0.87 s with OpenBLAS at 1).
  keep_blas_single_threaded();
}

// libtorch's thread count is OpenMP's per-thread setting (at::get_num_threads
// is omp_get_max_threads), so setting it here leaves other threads alone.
ScopedComputeThreads::ScopedComputeThreads(int n) {
#ifdef _OPENMP
  const int current = at::get_num_threads();
  if (n > 0 && n != current) {
    saved_ = current;
    omp_set_num_threads(n);
  }
#endif
}

ScopedComputeThreads::~ScopedComputeThreads() {
#ifdef _OPENMP
  if (saved_ > 0) omp_set_num_threads(saved_);
#endif
}

}  // namespace mf
