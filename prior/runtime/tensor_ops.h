// The arithmetic the Eigen runtime's networks are made of, on row-major float
// matrices whose rows are frames (time-major, the transpose of libtorch's
// channels-first [C, T] convolution layout): matrix products (through the
// system BLAS's sgemm, or Eigen's own kernels), 1D convolutions and their
// input gradients, layer normalisation and its gradient, group normalisation,
// leaky ReLU. Float32 throughout, like the libtorch networks they reproduce.
// Nothing here allocates when its outputs already have the right size, so a
// caller that keeps its buffers evaluates without allocating.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "prior/runtime/packed_gemm.h"

namespace mf::runtime {

/// A row-major float matrix: rows are frames, columns are channels.
using MatrixRXf = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
/// A row vector of channels (a bias, a normalisation's scale).
using RowVectorXf = Eigen::Matrix<float, 1, Eigen::Dynamic>;
using ConstMatrixRef = Eigen::Ref<const MatrixRXf>;
using MatrixRef = Eigen::Ref<MatrixRXf>;

/// Who multiplies matrices. Kernels: products with a network's weight run on
/// the runtime's own kernels (packed_gemm.h), the others on the BLAS; the
/// default where the CPU has AVX2 + FMA or AVX-512, and Blas where it has
/// neither. Blas: the system's libblas.so.3 (OpenBLAS; the BLAS libtorch
/// calls, with kernels chosen for the CPU when it loads). Eigen: Eigen's own
/// kernels (compiled for the build's instruction set: SSE2 on a generic x86-64
/// build). Process-wide.
enum class GemmBackend { Kernels, Blas, Eigen };
void set_gemm_backend(GemmBackend backend);
GemmBackend gemm_backend();

/// c = beta * c + op(a) * op(b), op(x) = x^T when its flag is set. Shapes must
/// agree (op(a) [m, k], op(b) [k, n], c [m, n]); beta = 0 ignores c's values.
void gemm(ConstMatrixRef a, bool transpose_a, ConstMatrixRef b, bool transpose_b, MatrixRef c, float beta);

/// A network's constant matrix: its values and, made on first use, op(values)
/// packed for the runtime's kernels, one copy per orientation used. Copies
/// share what was packed; packing is thread-safe.
class WeightMatrix {
 public:
  WeightMatrix() = default;
  explicit WeightMatrix(MatrixRXf values) : values_(std::move(values)) {}
  const MatrixRXf& values() const { return values_; }
  /// The values, to change: forgets what was packed from the old ones.
  MatrixRXf& mutable_values();
  Eigen::Index rows() const { return values_.rows(); }
  Eigen::Index cols() const { return values_.cols(); }
  Eigen::Index size() const { return values_.size(); }
  /// op(values) for the CPU's kernels (cpu_kernel_isa() must not be None).
  const PackedOperand& packed(bool transpose) const;

 private:
  MatrixRXf values_;
  PackedPair packs_;
};

/// gemm with a weight as the right operand: on the Kernels backend, the
/// runtime's kernels on op(b) packed (a is read in place, not transposed).
void gemm(ConstMatrixRef a, bool transpose_a, const WeightMatrix& b, bool transpose_b, MatrixRef c, float beta);

/// y = beta * y + op(a) * x for vectors x [op(a)'s columns] and y [its rows]
/// (the latent codes' products), on the same backend as gemm.
void gemv(ConstMatrixRef a, bool transpose_a, const Eigen::Ref<const Eigen::VectorXf>& x,
          Eigen::Ref<Eigen::VectorXf> y, float beta);

/// A 1D convolution's weights, per kernel tap: libtorch's weight [out, in, K]
/// as K matrices taps[k] [in, out] (taps[k](c, o) = weight[o, c, k]) and its
/// bias [out] (zeros when the convolution has none).
struct Conv1dWeights {
  std::vector<WeightMatrix> taps;
  RowVectorXf bias;
  /// false: the products go to the BLAS and nothing is packed (weights used
  /// once per solve, such as the encoders', whose packed copies would cost
  /// more memory and time than they save).
  bool kernels = true;
  int in() const { return static_cast<int>(taps.front().rows()); }
  int out() const { return static_cast<int>(taps.front().cols()); }
  int kernel() const { return static_cast<int>(taps.size()); }
  /// The taps as the operand of one product, packed for the runtime's kernels
  /// on first use (the taps must not change after): for the forward [K * in,
  /// out], tap k's rows at k * in; for the input gradient [K * out, in], tap
  /// K - 1 - j transposed at j * out.
  const PackedOperand& stacked(bool gradient) const;

 private:
  PackedPair stacked_;
};

/// Rows of a convolution's output over `padded_rows` input rows (padding
/// included) at `stride`: (padded_rows - K) / stride + 1.
int conv1d_output_rows(int padded_rows, int kernel, int stride);

/// y [R, out] = bias + sum_k x[stride * t + k] * taps[k] over the already padded
/// input x [padded_rows, in] (libtorch's conv1d with padding 0); y is resized.
/// On the Kernels backend, K > 1, stride 1, contiguous rows: one product over
/// the stacked taps, row t of its left operand being x's rows t .. t + K - 1.
void conv1d(ConstMatrixRef x_padded, const Conv1dWeights& w, int stride, MatrixRXf* y);

/// The input gradient of conv1d: g_x_padded[stride * t + k] += g_y[t] * taps[k]^T
/// (accumulates; g_x_padded [padded_rows, in] sized by the caller). On the
/// Kernels backend, K > 1, stride 1, contiguous rows: one product, g_y padded
/// with K - 1 rows of zeros at each end, against the stacked taps.
void conv1d_input_gradient(ConstMatrixRef g_y, const Conv1dWeights& w, int stride, MatrixRef g_x_padded);

/// x [T, C] replicated by `pad` rows at each end (the first and last row):
/// libtorch's replication_pad1d. `padded` is resized to [T + 2 pad, C].
void replication_pad_rows(ConstMatrixRef x, int pad, MatrixRXf* padded);

/// The gradient of replication_pad_rows: g [T + 2 pad, C] -> [T, C], the pad
/// rows' gradients summed into the end rows. `g_x` is resized.
void replication_pad_rows_gradient(ConstMatrixRef g_padded, int pad, MatrixRXf* g_x);

/// In place: x where x > 0, slope * x elsewhere.
void leaky_relu(MatrixRef x, float slope);

/// In place: g * (1 where pre > 0, slope elsewhere): the gradient of
/// leaky_relu at its input `pre` (libtorch's leaky_relu_backward). With
/// slope 0 the ReLU's, `pre` being its input or its output.
void leaky_relu_gradient(ConstMatrixRef pre, float slope, MatrixRef g);

/// Layer normalisation of every row of a [S, W] over its W values (biased
/// variance): y = (a - mean) * rstd * gamma + beta, rstd = 1 / sqrt(var + eps).
/// y, mean and rstd [S] are resized; mean and rstd are kept for the gradient.
void layer_norm_rows(ConstMatrixRef a, const RowVectorXf& gamma, const RowVectorXf& beta, float eps, MatrixRXf* y,
                     Eigen::VectorXf* mean, Eigen::VectorXf* rstd);

/// The input gradient of layer_norm_rows: from g_y [S, W] and the forward's
/// a, mean and rstd, g_a = rstd * (d - mean(d) - xhat * mean(d * xhat)) with
/// d = g_y * gamma and xhat = (a - mean) * rstd. `g_a` is resized.
void layer_norm_rows_gradient(ConstMatrixRef g_y, ConstMatrixRef a, const Eigen::VectorXf& mean,
                              const Eigen::VectorXf& rstd, const RowVectorXf& gamma, MatrixRXf* g_a);

/// In place, group normalisation of x [T, groups * n] (libtorch's GroupNorm on
/// the channels-first transpose): each group's n channels over all T rows
/// normalised together (biased variance, eps), then scaled and shifted per
/// channel by gamma and beta [groups * n].
void group_norm_columns(MatrixRef x, int groups, const RowVectorXf& gamma, const RowVectorXf& beta, float eps);

}  // namespace mf::runtime
