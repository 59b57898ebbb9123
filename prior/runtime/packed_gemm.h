// The runtime's own single-precision matrix kernels for products whose right
// operand is a network's constant weight: c = beta * c + a * op(b), with op(b)
// copied once into column panels that the kernels read in order. The runtime's
// products are small ([frames, 128..768] x [128..768, 128..768]), where a
// general BLAS spends much of its time packing the operands of every call: the
// weights are packed here once, and the activations are read in place. Built
// for AVX-512 and for AVX2 + FMA and chosen from the CPU when the process
// starts; on a CPU with neither, the runtime multiplies through the BLAS
// (tensor_ops.h). Single-threaded: the runtime runs one window per thread.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

namespace mf::runtime {

/// The instruction set of the kernels this process runs.
enum class KernelIsa { None, Avx2, Avx512 };

/// What the CPU supports, read once (AVX-512F first, then AVX2 with FMA).
KernelIsa cpu_kernel_isa();

/// op(b) [K, N] of a row-major matrix b in the kernels' layout: panels of
/// `panel_width()` columns, each K rows of that many values, the last panel
/// padded with zeros.
class PackedOperand {
 public:
  /// b [rows, cols] row-major with row stride `ld`; op(b) = b^T when `transpose`.
  PackedOperand(const float* b, int64_t rows, int64_t cols, int64_t ld, bool transpose, KernelIsa isa);
  int64_t depth() const { return depth_; }  ///< K
  int64_t width() const { return width_; }  ///< N
  KernelIsa isa() const { return isa_; }
  int panel_width() const { return panel_; }
  const float* panel(int64_t p) const { return values_.data() + p * depth_ * panel_; }

 private:
  int64_t depth_, width_;
  KernelIsa isa_;
  int panel_;
  std::vector<float> values_;
};

/// Two packed operands of one weight (say op(b) and op(b)^T), each made on
/// its first use, once across threads; copies share them.
class PackedPair {
 public:
  /// The operand `i` (0 or 1), made by make() (a unique_ptr<PackedOperand>) the first time.
  template <class Make>
  const PackedOperand& get(int i, Make&& make) const {
    std::call_once(state_->once[i], [&] { state_->op[i] = make(); });
    return *state_->op[i];
  }

 private:
  struct State {
    std::once_flag once[2];
    std::unique_ptr<PackedOperand> op[2];
  };
  std::shared_ptr<State> state_ = std::make_shared<State>();
};

/// c [M, N] (row stride ldc) = beta * c + a * op(b) for a [M, K] read at row
/// stride lda (rows may overlap: a convolution's taps are one product over
/// the input's rows read K values at a time). beta = 0 ignores c's values.
void packed_gemm(const float* a, int64_t rows, int64_t lda, const PackedOperand& b, float* c, int64_t ldc,
                 float beta);

}  // namespace mf::runtime
