#include "prior/runtime/packed_gemm.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define MF_X86_KERNELS 1
#endif

#include <algorithm>
#include <array>
#include <stdexcept>
#include <utility>

namespace mf::runtime {

namespace {

#ifdef MF_X86_KERNELS
// Depth of one pass over a panel: 256 rows of a 32-wide panel are 32 KiB,
// which stays in a 48 KiB L1 data cache while a panel's row blocks read it.
constexpr int64_t kDepthBlock = 256;

// Each kernel computes an MR x (panel width) block of c from MR rows of a and
// one panel: per k, the panel's row in vector registers and a[r, k] broadcast
// into an FMA per row and register. MR accumulator pairs stay in registers
// (AVX-512: 32 registers, 2 x 12 accumulators; AVX2: 16, 2 x 6).
template <int MR>
__attribute__((target("avx512f"))) void kernel_avx512(int64_t depth, const float* a, int64_t lda,
                                                      const float* panel, float* c, int64_t ldc, int64_t cols,
                                                      float beta) {
  __m512 lo[MR], hi[MR];
  for (int r = 0; r < MR; ++r) lo[r] = hi[r] = _mm512_setzero_ps();
  for (int64_t k = 0; k < depth; ++k) {
    const __m512 b0 = _mm512_loadu_ps(panel + 32 * k), b1 = _mm512_loadu_ps(panel + 32 * k + 16);
    for (int r = 0; r < MR; ++r) {
      const __m512 x = _mm512_set1_ps(a[r * lda + k]);
      lo[r] = _mm512_fmadd_ps(x, b0, lo[r]);
      hi[r] = _mm512_fmadd_ps(x, b1, hi[r]);
    }
  }
  const __mmask16 m0 = cols >= 16 ? 0xFFFF : static_cast<__mmask16>((1u << cols) - 1);
  const __mmask16 m1 = cols >= 32 ? 0xFFFF : cols <= 16 ? 0 : static_cast<__mmask16>((1u << (cols - 16)) - 1);
  const __m512 vb = _mm512_set1_ps(beta);
  for (int r = 0; r < MR; ++r) {
    float* row = c + r * ldc;
    if (beta != 0.0f) {
      lo[r] = _mm512_fmadd_ps(vb, _mm512_maskz_loadu_ps(m0, row), lo[r]);
      hi[r] = _mm512_fmadd_ps(vb, _mm512_maskz_loadu_ps(m1, row + 16), hi[r]);
    }
    _mm512_mask_storeu_ps(row, m0, lo[r]);
    _mm512_mask_storeu_ps(row + 16, m1, hi[r]);
  }
}

template <int MR>
__attribute__((target("avx2,fma"))) void kernel_avx2(int64_t depth, const float* a, int64_t lda, const float* panel,
                                                    float* c, int64_t ldc, int64_t cols, float beta) {
  __m256 lo[MR], hi[MR];
  for (int r = 0; r < MR; ++r) lo[r] = hi[r] = _mm256_setzero_ps();
  for (int64_t k = 0; k < depth; ++k) {
    const __m256 b0 = _mm256_loadu_ps(panel + 16 * k), b1 = _mm256_loadu_ps(panel + 16 * k + 8);
    for (int r = 0; r < MR; ++r) {
      const __m256 x = _mm256_broadcast_ss(a + r * lda + k);
      lo[r] = _mm256_fmadd_ps(x, b0, lo[r]);
      hi[r] = _mm256_fmadd_ps(x, b1, hi[r]);
    }
  }
  alignas(32) float block[16];
  for (int r = 0; r < MR; ++r) {
    float* row = c + r * ldc;
    if (cols == 16) {
      if (beta != 0.0f) {
        const __m256 vb = _mm256_set1_ps(beta);
        lo[r] = _mm256_fmadd_ps(vb, _mm256_loadu_ps(row), lo[r]);
        hi[r] = _mm256_fmadd_ps(vb, _mm256_loadu_ps(row + 8), hi[r]);
      }
      _mm256_storeu_ps(row, lo[r]);
      _mm256_storeu_ps(row + 8, hi[r]);
      continue;
    }
    _mm256_store_ps(block, lo[r]);
    _mm256_store_ps(block + 8, hi[r]);
    for (int64_t j = 0; j < cols; ++j) row[j] = block[j] + (beta != 0.0f ? beta * row[j] : 0.0f);
  }
}

using Kernel = void (*)(int64_t, const float*, int64_t, const float*, float*, int64_t, int64_t, float);

template <template <int> class Table, int... R>
constexpr std::array<Kernel, sizeof...(R)> kernels(std::integer_sequence<int, R...>) {
  return {Table<R + 1>::fn...};
}
template <int MR>
struct Avx512 {
  static constexpr Kernel fn = kernel_avx512<MR>;
};
template <int MR>
struct Avx2 {
  static constexpr Kernel fn = kernel_avx2<MR>;
};

constexpr auto kAvx512 = kernels<Avx512>(std::make_integer_sequence<int, 12>());
constexpr auto kAvx2 = kernels<Avx2>(std::make_integer_sequence<int, 6>());

#endif  // MF_X86_KERNELS

KernelIsa detect() {
#ifdef MF_X86_KERNELS
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f")) return KernelIsa::Avx512;
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return KernelIsa::Avx2;
#endif
  return KernelIsa::None;
}

}  // namespace

KernelIsa cpu_kernel_isa() {
  static const KernelIsa isa = detect();
  return isa;
}

PackedOperand::PackedOperand(const float* b, int64_t rows, int64_t cols, int64_t ld, bool transpose, KernelIsa isa)
    : depth_(transpose ? cols : rows), width_(transpose ? rows : cols), isa_(isa) {
  if (isa == KernelIsa::None) throw std::logic_error("PackedOperand: no kernel instruction set");
  panel_ = isa == KernelIsa::Avx512 ? 32 : 16;
  const int64_t panels = (width_ + panel_ - 1) / panel_;
  values_.assign(static_cast<size_t>(panels * depth_ * panel_), 0.0f);
  for (int64_t p = 0; p < panels; ++p) {
    float* out = values_.data() + p * depth_ * panel_;
    const int64_t n = std::min<int64_t>(panel_, width_ - p * panel_);
    for (int64_t k = 0; k < depth_; ++k)
      for (int64_t j = 0; j < n; ++j) {
        const int64_t col = p * panel_ + j;
        out[k * panel_ + j] = transpose ? b[col * ld + k] : b[k * ld + col];
      }
  }
}

void packed_gemm(const float* a, int64_t rows, int64_t lda, const PackedOperand& b, float* c, int64_t ldc,
                 float beta) {
#ifndef MF_X86_KERNELS
  (void)a, (void)rows, (void)lda, (void)b, (void)c, (void)ldc, (void)beta;
  throw std::logic_error("packed_gemm: no kernels on this architecture");
#else
  const bool wide = b.isa() == KernelIsa::Avx512;
  const Kernel* table = wide ? kAvx512.data() : kAvx2.data();
  const int64_t max_rows = wide ? static_cast<int64_t>(kAvx512.size()) : static_cast<int64_t>(kAvx2.size());
  const int64_t K = b.depth(), N = b.width(), P = b.panel_width();
  for (int64_t k0 = 0; k0 < K; k0 += kDepthBlock) {
    const int64_t depth = std::min(kDepthBlock, K - k0);
    const float pass_beta = k0 == 0 ? beta : 1.0f;
    for (int64_t p = 0; p * P < N; ++p) {
      const float* panel = b.panel(p) + k0 * P;
      const int64_t cols = std::min(P, N - p * P);
      for (int64_t i = 0; i < rows; i += max_rows) {
        const int64_t mr = std::min(max_rows, rows - i);
        table[mr - 1](depth, a + i * lda + k0, lda, panel, c + i * ldc + p * P, ldc, cols, pass_beta);
      }
    }
  }
#endif
}

}  // namespace mf::runtime
