// The process's compute threads and the BLAS behind libtorch's matrix
// products. libtorch's at::set_num_threads sizes its own intra-op pool only;
// OpenBLAS (the libblas.so.3 that scripts/install-deps.sh selects) keeps a pool
// of its own, one thread per core unless told otherwise, so a "1 thread" run
// would still multiply matrices on every core, and a 2-thread run nests two
// pools that thrash. set_compute_threads sizes libtorch's pool and keeps
// OpenBLAS's at 1.
#pragma once

#include <string>

namespace mf {

/// at::set_num_threads(n) and, when OpenBLAS is loaded, openblas_set_num_threads(1).
/// n >= 1.
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

/// Only the second half: OpenBLAS's pool at 1 thread, libtorch's untouched. For
/// a library whose caller never chose a thread count.
void keep_blas_single_threaded();

/// The file (links resolved) of the library whose sgemm_ serves libtorch's
/// float matrix products in this process, e.g.
/// "/usr/lib/x86_64-linux-gnu/openblas-pthread/libblas.so.3", or "unknown".
/// For benchmark headers and the BLAS test.
std::string blas_library();

/// OpenBLAS's name of the kernels it runs in this process
/// (openblas_get_corename(): "SkylakeX", "Haswell", "Zen", ...; chosen when it
/// was loaded; docs/BLAS.md), or "" when the BLAS is not OpenBLAS.
std::string openblas_core();

/// blas_library() and, for OpenBLAS, its kernels: the BLAS line of benchmark headers.
std::string describe_blas();

}  // namespace mf
