#include "prior/runtime/tensor_ops.h"

#include <atomic>
#include <cmath>
#include <stdexcept>
#include <string>

// The Fortran BLAS interface every libblas.so.3 exports (column-major).
extern "C" void sgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k,
                       const float* alpha, const float* a, const int* lda, const float* b, const int* ldb,
                       const float* beta, float* c, const int* ldc);
extern "C" void sgemv_(const char* trans, const int* m, const int* n, const float* alpha, const float* a,
                       const int* lda, const float* x, const int* incx, const float* beta, float* y,
                       const int* incy);

namespace mf::runtime {

namespace {

std::atomic<GemmBackend> g_backend{cpu_kernel_isa() == KernelIsa::None ? GemmBackend::Blas : GemmBackend::Kernels};

using StridedMap = Eigen::Map<MatrixRXf, 0, Eigen::OuterStride<>>;
using ConstStridedMap = Eigen::Map<const MatrixRXf, 0, Eigen::OuterStride<>>;

// Row-major c = a * b is column-major c^T = b^T * a^T: the same memory, the
// operands swapped.
void blas_gemm(ConstMatrixRef a, bool ta, ConstMatrixRef b, bool tb, MatrixRef c, float beta, int k) {
  const int m = static_cast<int>(c.rows()), n = static_cast<int>(c.cols());
  const int lda = static_cast<int>(a.outerStride()), ldb = static_cast<int>(b.outerStride());
  const int ldc = static_cast<int>(c.outerStride());
  const float alpha = 1.0f;
  sgemm_(tb ? "T" : "N", ta ? "T" : "N", &n, &m, &k, &alpha, b.data(), &ldb, a.data(), &lda, &beta, c.data(), &ldc);
}

template <class A, class B>
void eigen_gemm(const A& a, const B& b, MatrixRef c, float beta) {
  if (beta == 0.0f) {
    c.noalias() = a * b;
    return;
  }
  if (beta != 1.0f) c *= beta;
  c.noalias() += a * b;
}

bool kernels_on() { return g_backend.load() == GemmBackend::Kernels && cpu_kernel_isa() != KernelIsa::None; }

}  // namespace

void set_gemm_backend(GemmBackend backend) { g_backend.store(backend); }
GemmBackend gemm_backend() { return g_backend.load(); }

MatrixRXf& WeightMatrix::mutable_values() {
  packs_ = PackedPair();
  return values_;
}

const PackedOperand& WeightMatrix::packed(bool transpose) const {
  return packs_.get(transpose ? 1 : 0, [&] {
    return std::make_unique<PackedOperand>(values_.data(), values_.rows(), values_.cols(), values_.outerStride(),
                                           transpose, cpu_kernel_isa());
  });
}

void gemm(ConstMatrixRef a, bool transpose_a, const WeightMatrix& b, bool transpose_b, MatrixRef c, float beta) {
  const Eigen::Index m = transpose_a ? a.cols() : a.rows(), k = transpose_a ? a.rows() : a.cols();
  const Eigen::Index n = transpose_b ? b.rows() : b.cols();
  if (!kernels_on() || transpose_a || m == 0 || n == 0 || k == 0 || m != c.rows() || n != c.cols() ||
      k != (transpose_b ? b.cols() : b.rows())) {
    return gemm(a, transpose_a, b.values(), transpose_b, c, beta);  // checks the shapes
  }
  packed_gemm(a.data(), m, a.outerStride(), b.packed(transpose_b), c.data(), c.outerStride(), beta);
}

void gemm(ConstMatrixRef a, bool transpose_a, ConstMatrixRef b, bool transpose_b, MatrixRef c, float beta) {
  const Eigen::Index m = transpose_a ? a.cols() : a.rows(), k = transpose_a ? a.rows() : a.cols();
  const Eigen::Index kb = transpose_b ? b.cols() : b.rows(), n = transpose_b ? b.rows() : b.cols();
  if (m != c.rows() || n != c.cols() || k != kb) {
    throw std::logic_error("runtime gemm: shapes [" + std::to_string(m) + ", " + std::to_string(k) + "] x [" +
                           std::to_string(kb) + ", " + std::to_string(n) + "] -> [" + std::to_string(c.rows()) +
                           ", " + std::to_string(c.cols()) + "]");
  }
  if (m == 0 || n == 0) return;
  if (k == 0) {
    if (beta == 0.0f) c.setZero();
    else c *= beta;
    return;
  }
  if (gemm_backend() != GemmBackend::Eigen) return blas_gemm(a, transpose_a, b, transpose_b, c, beta, static_cast<int>(k));
  if (!transpose_a && !transpose_b) eigen_gemm(a, b, c, beta);
  else if (transpose_a && !transpose_b) eigen_gemm(a.transpose(), b, c, beta);
  else if (!transpose_a) eigen_gemm(a, b.transpose(), c, beta);
  else eigen_gemm(a.transpose(), b.transpose(), c, beta);
}

void gemv(ConstMatrixRef a, bool transpose_a, const Eigen::Ref<const Eigen::VectorXf>& x,
          Eigen::Ref<Eigen::VectorXf> y, float beta) {
  const Eigen::Index rows = transpose_a ? a.cols() : a.rows(), cols = transpose_a ? a.rows() : a.cols();
  if (x.size() != cols || y.size() != rows) {
    throw std::logic_error("runtime gemv: [" + std::to_string(rows) + ", " + std::to_string(cols) + "] x [" +
                           std::to_string(x.size()) + "] -> [" + std::to_string(y.size()) + "]");
  }
  if (rows == 0) return;
  if (cols == 0 || gemm_backend() == GemmBackend::Eigen) {
    if (beta == 0.0f) y.setZero();
    else y *= beta;
    if (transpose_a) y.noalias() += a.transpose() * x;
    else y.noalias() += a * x;
    return;
  }
  // Row-major a is column-major a^T: transposed for a * x, as is for a^T * x.
  const int m = static_cast<int>(a.cols()), n = static_cast<int>(a.rows()), lda = static_cast<int>(a.outerStride());
  const int one = 1;
  const float alpha = 1.0f;
  sgemv_(transpose_a ? "N" : "T", &m, &n, &alpha, a.data(), &lda, x.data(), &one, &beta, y.data(), &one);
}

int conv1d_output_rows(int padded_rows, int kernel, int stride) { return (padded_rows - kernel) / stride + 1; }

const PackedOperand& Conv1dWeights::stacked(bool gradient) const {
  return stacked_.get(gradient ? 1 : 0, [&] {
    const int K = kernel(), rows = gradient ? out() : in(), cols = gradient ? in() : out();
    MatrixRXf b(K * rows, cols);
    for (int k = 0; k < K; ++k) {
      if (gradient) b.middleRows(k * rows, rows) = taps[K - 1 - k].values().transpose();
      else b.middleRows(k * rows, rows) = taps[k].values();
    }
    return std::make_unique<PackedOperand>(b.data(), b.rows(), b.cols(), b.cols(), false, cpu_kernel_isa());
  });
}

void conv1d(ConstMatrixRef x_padded, const Conv1dWeights& w, int stride, MatrixRXf* y) {
  const int rows = conv1d_output_rows(static_cast<int>(x_padded.rows()), w.kernel(), stride);
  const Eigen::Index ld = x_padded.outerStride();
  y->resize(rows, w.out());
  y->rowwise() = w.bias;
  // The per-tap products below check the shapes; the fused one reads K rows at a time.
  if (w.kernels && stride == 1 && w.kernel() > 1 && x_padded.cols() == w.in() && ld == x_padded.cols() && rows > 0 &&
      kernels_on()) {
    packed_gemm(x_padded.data(), rows, ld, w.stacked(false), y->data(), y->cols(), 1.0f);
    return;
  }
  for (int k = 0; k < w.kernel(); ++k) {
    const ConstStridedMap xk(x_padded.data() + k * ld, rows, x_padded.cols(), Eigen::OuterStride<>(stride * ld));
    if (w.kernels) gemm(xk, false, w.taps[k], false, *y, 1.0f);
    else gemm(xk, false, w.taps[k].values(), false, *y, 1.0f);
  }
}

void conv1d_input_gradient(ConstMatrixRef g_y, const Conv1dWeights& w, int stride, MatrixRef g_x_padded) {
  const Eigen::Index ld = g_x_padded.outerStride();
  const int K = w.kernel();
  if (w.kernels && stride == 1 && K > 1 && g_y.cols() == w.out() && g_x_padded.cols() == w.in() &&
      ld == g_x_padded.cols() && g_y.rows() > 0 && g_x_padded.rows() == g_y.rows() + K - 1 && kernels_on()) {
    thread_local MatrixRXf padded;  // g_y between K - 1 rows of zeros at each end
    padded.resize(g_y.rows() + 2 * (K - 1), g_y.cols());
    padded.topRows(K - 1).setZero();
    padded.bottomRows(K - 1).setZero();
    padded.middleRows(K - 1, g_y.rows()) = g_y;
    packed_gemm(padded.data(), g_x_padded.rows(), padded.cols(), w.stacked(true), g_x_padded.data(), ld, 1.0f);
    return;
  }
  for (int k = 0; k < w.kernel(); ++k) {
    StridedMap gk(g_x_padded.data() + k * ld, g_y.rows(), g_x_padded.cols(), Eigen::OuterStride<>(stride * ld));
    if (w.kernels) gemm(g_y, false, w.taps[k], true, gk, 1.0f);
    else gemm(g_y, false, w.taps[k].values(), true, gk, 1.0f);
  }
}

void replication_pad_rows(ConstMatrixRef x, int pad, MatrixRXf* padded) {
  const Eigen::Index T = x.rows();
  padded->resize(T + 2 * pad, x.cols());
  padded->middleRows(pad, T) = x;
  for (int r = 0; r < pad; ++r) {
    padded->row(r) = x.row(0);
    padded->row(pad + T + r) = x.row(T - 1);
  }
}

void replication_pad_rows_gradient(ConstMatrixRef g_padded, int pad, MatrixRXf* g_x) {
  const Eigen::Index T = g_padded.rows() - 2 * pad;
  *g_x = g_padded.middleRows(pad, T);
  for (int r = 0; r < pad; ++r) {
    g_x->row(0) += g_padded.row(r);
    g_x->row(T - 1) += g_padded.row(pad + T + r);
  }
}

// Eigen's select() compiles to a branch per value here, mispredicted half the
// time on activations; these loops vectorise (the factor as a named
// temporary: GCC does not if-convert `v *= p > 0 ? 1 : slope`).
void leaky_relu(MatrixRef x, float slope) {
  for (Eigen::Index r = 0; r < x.rows(); ++r) {
    float* __restrict v = x.row(r).data();
    for (Eigen::Index c = 0; c < x.cols(); ++c) {
      const float factor = v[c] > 0.0f ? 1.0f : slope;
      v[c] = v[c] * factor;
    }
  }
}

void leaky_relu_gradient(ConstMatrixRef pre, float slope, MatrixRef g) {
  for (Eigen::Index r = 0; r < g.rows(); ++r) {
    const float* __restrict p = pre.row(r).data();
    float* __restrict v = g.row(r).data();
    for (Eigen::Index c = 0; c < g.cols(); ++c) {
      const float factor = p[c] > 0.0f ? 1.0f : slope;
      v[c] = v[c] * factor;
    }
  }
}

void layer_norm_rows(ConstMatrixRef a, const RowVectorXf& gamma, const RowVectorXf& beta, float eps, MatrixRXf* y,
                     Eigen::VectorXf* mean, Eigen::VectorXf* rstd) {
  const Eigen::Index S = a.rows();
  y->resize(S, a.cols());
  mean->resize(S);
  rstd->resize(S);
  for (Eigen::Index i = 0; i < S; ++i) {
    const float m = a.row(i).mean();
    const float var = (a.row(i).array() - m).square().mean();
    const float r = 1.0f / std::sqrt(var + eps);
    (*mean)[i] = m;
    (*rstd)[i] = r;
    y->row(i) = ((a.row(i).array() - m) * r * gamma.array() + beta.array()).matrix();
  }
}

void layer_norm_rows_gradient(ConstMatrixRef g_y, ConstMatrixRef a, const Eigen::VectorXf& mean,
                              const Eigen::VectorXf& rstd, const RowVectorXf& gamma, MatrixRXf* g_a) {
  const Eigen::Index S = a.rows();
  g_a->resize(S, a.cols());
  for (Eigen::Index i = 0; i < S; ++i) {
    const auto d = g_y.row(i).array() * gamma.array();
    const auto xhat = (a.row(i).array() - mean[i]) * rstd[i];
    const float mean_d = d.mean(), mean_dx = (d * xhat).mean();
    g_a->row(i) = (rstd[i] * (d - mean_d - xhat * mean_dx)).matrix();
  }
}

void group_norm_columns(MatrixRef x, int groups, const RowVectorXf& gamma, const RowVectorXf& beta, float eps) {
  const Eigen::Index n = x.cols() / groups;
  for (int j = 0; j < groups; ++j) {
    auto block = x.middleCols(j * n, n);
    const float m = block.mean();
    const float var = (block.array() - m).square().mean();
    const float r = 1.0f / std::sqrt(var + eps);
    for (Eigen::Index t = 0; t < block.rows(); ++t) {
      block.row(t) = ((block.row(t).array() - m) * r * gamma.segment(j * n, n).array() +
                      beta.segment(j * n, n).array()).matrix();
    }
  }
}

}  // namespace mf::runtime
