#include "tasks/renav/soft_dtw_kernels.h"

// The cost products are small: never let Eigen start OpenMP threads for them
// (it would when this file is compiled with -fopenmp).
#ifndef EIGEN_DONT_PARALLELIZE
#define EIGEN_DONT_PARALLELIZE
#endif
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "prior/motion/errors.h"

namespace mf::sdtw {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int64_t kTile = 128;
// Soft-argmin weights below exp(-345) ~ 1e-150 and alignment weights below
// 1e-150 are set to 0: the products of the backward then never leave the normal
// range (denormal arithmetic and the underflow path of exp() cost 10-100x more
// than normal numbers), and the change is far below double rounding of E in [0, 1].
constexpr double kMinExponent = -345.0;
constexpr double kMinWeight = 1e-150;

template <typename T>
struct ForwardArgs {
  const T* D;  // m x n, row-major
  Dims dm;
  double gamma, inv_gamma;
  double* R;
  double* P;  // null: no gradient wanted
};

// One cell: softmin over the three predecessors with the log-sum-exp shift by
// the smallest one, whose exponential is exactly 1, so two exp and one log.
template <typename T>
inline void forward_cell(const ForwardArgs<T>& f, int64_t i, int64_t j) {
  const int64_t rs = f.dm.rs();
  const double a = f.R[(i - 1) * rs + j - 1], b = f.R[(i - 1) * rs + j], c = f.R[i * rs + j - 1];
  const double ab_lo = std::min(a, b), ab_hi = std::max(a, b);
  const double lo = std::min(ab_lo, c), hi = std::max(ab_hi, c);  // lo is finite: some predecessor is
  const double mid = std::max(ab_lo, std::min(ab_hi, c));
  // Ties give exactly 0 even when 1/gamma overflows (0 * inf would be NaN).
  const double t_mid = lo == mid ? 0.0 : (lo - mid) * f.inv_gamma;
  const double t_hi = lo == hi ? 0.0 : (lo - hi) * f.inv_gamma;
  const double e_mid = t_mid > kMinExponent ? std::exp(std::max(t_mid, kMinExponent)) : 0.0;
  const double e_hi = t_hi > kMinExponent ? std::exp(std::max(t_hi, kMinExponent)) : 0.0;
  const double s = 1.0 + e_mid + e_hi;  // in [1, 3]
  f.R[i * rs + j] = static_cast<double>(f.D[(i - 1) * f.dm.n + j - 1]) + (lo - f.gamma * std::log(s));
  if (f.P) {
    const double inv_s = 1.0 / s;
    double* p = f.P + 3 * (i * f.dm.ps() + j);
    p[0] = (a == lo ? 1.0 : a == mid ? e_mid : e_hi) * inv_s;
    p[1] = (b == lo ? 1.0 : b == mid ? e_mid : e_hi) * inv_s;
    p[2] = (c == lo ? 1.0 : c == mid ? e_mid : e_hi) * inv_s;
  }
}

// Rows [i0, i1) and columns [j0, j1) (1-based cells), two rows at a time with
// the second one column behind, so that two independent cells are in flight
// (the recursion is otherwise one long chain of exp/log latencies).
template <typename T>
void forward_block(const ForwardArgs<T>& f, int64_t i0, int64_t i1, int64_t j0, int64_t j1) {
  int64_t i = i0;
  for (; i + 2 <= i1; i += 2) {
    forward_cell(f, i, j0);
    for (int64_t j = j0 + 1; j < j1; ++j) {
      forward_cell(f, i, j);
      forward_cell(f, i + 1, j - 1);
    }
    forward_cell(f, i + 1, j1 - 1);
  }
  for (; i < i1; ++i)
    for (int64_t j = j0; j < j1; ++j) forward_cell(f, i, j);
}

// The same block backwards: G[i][j] = sum over the successors of (i, j) of
// G[successor] * the probability that the successor came from (i, j).
void backward_block(Dims dm, const double* P, double* G, int64_t i0, int64_t i1, int64_t j0, int64_t j1) {
  const int64_t ps = dm.ps();
  for (int64_t i = i1 - 1; i >= i0; --i) {
    double* Gi = G + i * ps;
    const double* Gdown = G + (i + 1) * ps;
    const double* Pi = P + 3 * i * ps;
    const double* Pdown = P + 3 * (i + 1) * ps;
    for (int64_t j = j1 - 1; j >= j0; --j) {
      const double g =
          Gdown[j + 1] * Pdown[3 * (j + 1)] + Gdown[j] * Pdown[3 * j + 1] + Gi[j + 1] * Pi[3 * (j + 1) + 2];
      Gi[j] = g >= kMinWeight ? g : 0.0;
    }
  }
}

// Runs `block(i0, i1, j0, j1)` over the cells 1..m x 1..n: one block when
// serial, else kTile x kTile tiles by anti-diagonals (in reverse for the backward).
template <typename F>
void run_blocks(Dims dm, ParallelFor wavefront, bool reverse, const F& block) {
  if (!wavefront) {
    block(1, dm.m + 1, 1, dm.n + 1);
    return;
  }
  const int64_t ti_count = (dm.m + kTile - 1) / kTile, tj_count = (dm.n + kTile - 1) / kTile;
  const int64_t diagonals = ti_count + tj_count - 1;
  auto tile = [&](int64_t ti, int64_t tj) {
    block(1 + ti * kTile, 1 + std::min(dm.m, (ti + 1) * kTile), 1 + tj * kTile, 1 + std::min(dm.n, (tj + 1) * kTile));
  };
  for (int64_t k = 0; k < diagonals; ++k) {
    const int64_t d = reverse ? diagonals - 1 - k : k;
    const int64_t lo = std::max<int64_t>(0, d - tj_count + 1), hi = std::min(d, ti_count - 1);
    if (lo == hi) {
      tile(lo, d - lo);
      continue;
    }
    wavefront(lo, hi + 1, 1, [&](int64_t begin, int64_t end) {
      for (int64_t ti = begin; ti < end; ++ti) tile(ti, d - ti);
    });
  }
}

}  // namespace

template <typename T>
double item_forward(const T* D, Dims dm, double gamma, double* P, ParallelFor wavefront) {
  const int64_t rs = dm.rs();
  std::unique_ptr<double[]> R(new double[(dm.m + 1) * rs]);
  R[0] = 0.0;
  for (int64_t j = 1; j <= dm.n; ++j) R[j] = kInf;
  for (int64_t i = 1; i <= dm.m; ++i) R[i * rs] = kInf;
  if (P) {
    const int64_t ps = dm.ps();
    std::fill(P + 3 * (dm.m + 1) * ps, P + 3 * (dm.m + 2) * ps, 0.0);
    for (int64_t i = 0; i <= dm.m; ++i) std::fill(P + 3 * (i * ps + dm.n + 1), P + 3 * (i * ps + dm.n + 2), 0.0);
    P[3 * ((dm.m + 1) * ps + dm.n + 1)] = 1.0;
  }
  const ForwardArgs<T> f{D, dm, gamma, 1.0 / gamma, R.get(), P};
  run_blocks(dm, wavefront, false,
             [&](int64_t i0, int64_t i1, int64_t j0, int64_t j1) { forward_block(f, i0, i1, j0, j1); });
  return R[dm.m * rs + dm.n];
}

std::unique_ptr<double[]> item_backward(const double* P, Dims dm, ParallelFor wavefront) {
  std::unique_ptr<double[]> G(new double[dm.g_size()]);
  const int64_t ps = dm.ps();
  std::fill(G.get() + (dm.m + 1) * ps, G.get() + (dm.m + 2) * ps, 0.0);
  for (int64_t i = 0; i <= dm.m; ++i) G[i * ps + dm.n + 1] = 0.0;
  G[(dm.m + 1) * ps + dm.n + 1] = 1.0;
  run_blocks(dm, wavefront, true,
             [&](int64_t i0, int64_t i1, int64_t j0, int64_t j1) { backward_block(dm, P, G.get(), i0, i1, j0, j1); });
  return G;
}
template double item_forward<float>(const float*, Dims, double, double*, ParallelFor);
template double item_forward<double>(const double*, Dims, double, double*, ParallelFor);

void pair_cost(const double* a, int64_t m, const double* b, int64_t n, int64_t d, double* D) {
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const Eigen::Map<const RowMajor> A(a, m, d), Bm(b, n, d);
  Eigen::Map<RowMajor> Dm(D, m, n);
  Dm.noalias() = A * Bm.transpose();
  const Eigen::VectorXd na = A.rowwise().squaredNorm(), nb = Bm.rowwise().squaredNorm();
  for (int64_t i = 0; i < m; ++i)
    for (int64_t j = 0; j < n; ++j) D[i * n + j] = std::max(0.0, (na[i] + nb[j]) - 2.0 * D[i * n + j]);
}

void pair_grad(const double* G, Dims dm, const double* a, const double* b, int64_t d, double w, double* ga, double* gb,
               ParallelFor parallel) {
  const int64_t ps = dm.ps();
  const double* E = G + ps + 1;  // E[i][j] = E[i * ps + j]
  const double scale = 2.0 * w;
  auto rows_of_a = [&](int64_t i0, int64_t i1) {
    std::vector<double> acc(d);
    for (int64_t i = i0; i < i1; ++i) {
      std::fill(acc.begin(), acc.end(), 0.0);
      double sum = 0.0;
      for (int64_t j = 0; j < dm.n; ++j) {
        const double e = E[i * ps + j];
        if (e == 0.0) continue;  // common far from the path at small gamma
        sum += e;
        for (int64_t k = 0; k < d; ++k) acc[k] += e * b[j * d + k];
      }
      for (int64_t k = 0; k < d; ++k) ga[i * d + k] += scale * (sum * a[i * d + k] - acc[k]);
    }
  };
  auto rows_of_b = [&](int64_t j0, int64_t j1) {
    std::vector<double> acc((j1 - j0) * d, 0.0), sum(j1 - j0, 0.0);
    for (int64_t i = 0; i < dm.m; ++i)
      for (int64_t j = j0; j < j1; ++j) {
        const double e = E[i * ps + j];
        if (e == 0.0) continue;
        sum[j - j0] += e;
        for (int64_t k = 0; k < d; ++k) acc[(j - j0) * d + k] += e * a[i * d + k];
      }
    for (int64_t j = j0; j < j1; ++j)
      for (int64_t k = 0; k < d; ++k) gb[j * d + k] += scale * (sum[j - j0] * b[j * d + k] - acc[(j - j0) * d + k]);
  };
  if (parallel) {
    parallel(0, dm.m, 1, rows_of_a);
    parallel(0, dm.n, 1, rows_of_b);
  } else {
    rows_of_a(0, dm.m);
    rows_of_b(0, dm.n);
  }
}

namespace {

void check_sequences(const RowMatrixXd& x, const RowMatrixXd& y, double gamma) {
  constexpr const char* fn = "soft_dtw_divergence";
  if (!std::isfinite(gamma) || gamma <= 0.0)
    throw InputError(std::string(fn) + ": gamma must be finite and > 0, got " + std::to_string(gamma));
  if (x.rows() < 1 || y.rows() < 1 || x.cols() < 1)
    throw InputError(std::string(fn) + ": sequences must have at least one frame and one value per frame");
  if (x.cols() != y.cols())
    throw InputError(std::string(fn) + ": x and y must have the same feature size d, got " + std::to_string(x.cols()) +
                     " and " + std::to_string(y.cols()));
  if (!x.allFinite() || !y.allFinite())
    throw InputError(std::string(fn) + ": x or y has non-finite values (NaN or infinity)");
}

// sdtw(a, b) of two sequences with d values per frame; P as item_forward's.
double pair_value(const double* a, int64_t m, const double* b, int64_t n, int64_t d, double gamma, double* P) {
  std::unique_ptr<double[]> D(new double[m * n]);
  pair_cost(a, m, b, n, d, D.get());
  return item_forward(D.get(), Dims{m, n}, gamma, P, nullptr);
}

double checked(double value) {
  if (!std::isfinite(value))
    throw InputError("soft_dtw_divergence: the accumulated cost overflowed (costs too large for double)");
  return value;
}

}  // namespace

double self_value(const RowMatrixXd& y, double gamma) {
  check_sequences(y, y, gamma);
  return checked(pair_value(y.data(), y.rows(), y.data(), y.rows(), y.cols(), gamma, nullptr));
}

// The order of the sums is soft_dtw.cc's (sdtw(x, y), then x with itself, then
// y with itself; gradients of the first pair, then of the second), so that both
// give the same bits.
double divergence(const RowMatrixXd& x, const RowMatrixXd& y, double gamma, RowMatrixXd* grad_x,
                  const double* self_y) {
  check_sequences(x, y, gamma);
  const int64_t m = x.rows(), n = y.rows(), d = x.cols();
  const Dims xy{m, n}, xx{m, m};
  std::unique_ptr<double[]> p_xy, p_xx;
  if (grad_x) {
    p_xy.reset(new double[xy.p_size()]);
    p_xx.reset(new double[xx.p_size()]);
  }
  double total = 0.0;
  total += 1.0 * pair_value(x.data(), m, y.data(), n, d, gamma, p_xy.get());
  total += -0.5 * pair_value(x.data(), m, x.data(), m, d, gamma, p_xx.get());
  total += -0.5 * (self_y ? *self_y : pair_value(y.data(), n, y.data(), n, d, gamma, nullptr));
  checked(total);
  if (grad_x) {
    grad_x->setZero(m, d);
    std::vector<double> scratch_y(n * d);
    auto g_xy = item_backward(p_xy.get(), xy, nullptr);
    pair_grad(g_xy.get(), xy, x.data(), y.data(), d, 1.0, grad_x->data(), scratch_y.data(), nullptr);
    auto g_xx = item_backward(p_xx.get(), xx, nullptr);
    pair_grad(g_xx.get(), xx, x.data(), x.data(), d, -0.5, grad_x->data(), grad_x->data(), nullptr);
  }
  return total;
}

}  // namespace mf::sdtw
