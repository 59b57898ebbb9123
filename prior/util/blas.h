// The BLAS behind the matrix products (the Eigen runtime's, prior/runtime/,
// and libtorch's): which library serves them, and the size of its own thread
// pool. OpenBLAS (the libblas.so.3 that scripts/install-deps.sh selects) keeps
// a pool of its own, one thread per core unless told otherwise.
#pragma once

#include <string>

namespace mf {

/// openblas_set_num_threads(n) when OpenBLAS is loaded; nothing otherwise.
/// n >= 1.
void set_blas_threads(int n);

/// set_blas_threads(1).
void keep_blas_single_threaded();

/// The file (links resolved) of the library whose sgemm_ serves the float
/// matrix products in this process, e.g.
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
