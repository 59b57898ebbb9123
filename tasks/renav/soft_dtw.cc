#include "tasks/renav/soft_dtw.h"

#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <torch/csrc/autograd/custom_function.h>

// The cost products are small: never let Eigen start OpenMP threads for them
// (it would when this file is compiled with -fopenmp).
#ifndef EIGEN_DONT_PARALLELIZE
#define EIGEN_DONT_PARALLELIZE
#endif
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "prior/motion/errors.h"

namespace mf {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Below this many cells in a call, everything stays on the calling thread: waking
// a second OpenMP thread costs milliseconds when the other core is busy.
constexpr int64_t kMinParallelCells = int64_t{1} << 16;
// A single matrix runs as a tiled wavefront when both sides reach this.
constexpr int64_t kWavefrontMinSide = 512;
constexpr int64_t kTile = 128;
// Soft-argmin weights below exp(-345) ~ 1e-150 and alignment weights below
// 1e-150 are set to 0: the products of the backward then never leave the normal
// range (denormal arithmetic and the underflow path of exp() cost 10-100x more
// than normal numbers), and the change is far below double rounding of E in [0, 1].
constexpr double kMinExponent = -345.0;
constexpr double kMinWeight = 1e-150;

std::string shape_string(const at::Tensor& t) {
  std::string s = "[";
  for (int64_t i = 0; i < t.dim(); ++i) s += (i ? ", " : "") + std::to_string(t.size(i));
  return s + "]";
}

void require_float_cpu(const at::Tensor& t, const char* fn, const char* what) {
  if (!t.defined()) throw InputError(std::string(fn) + ": " + what + " is an undefined tensor");
  if (!t.device().is_cpu()) throw InputError(std::string(fn) + ": " + what + " must be a CPU tensor");
  if (t.scalar_type() != at::kFloat && t.scalar_type() != at::kDouble)
    throw InputError(std::string(fn) + ": " + what + " must be float32 or float64, got " +
                     std::string(c10::toString(t.scalar_type())));
}

void require_gamma(double gamma, const char* fn) {
  if (!std::isfinite(gamma) || gamma <= 0.0)
    throw InputError(std::string(fn) + ": gamma must be finite and > 0, got " + std::to_string(gamma));
}

// A plain loop (at::isfinite would start threads for large tensors).
void require_finite(const at::Tensor& contiguous, const char* fn, const char* what) {
  bool ok = true;
  AT_DISPATCH_FLOATING_TYPES(contiguous.scalar_type(), "soft_dtw_finite", [&] {
    const scalar_t* p = contiguous.data_ptr<scalar_t>();
    for (int64_t k = 0, n = contiguous.numel(); k < n; ++k) ok &= std::isfinite(p[k]);
  });
  if (!ok) throw InputError(std::string(fn) + ": " + what + " has non-finite values (NaN or infinity)");
}

// The values [B] as a tensor of `options`' type, each checked for overflow.
at::Tensor checked_values(const std::vector<double>& values, const at::TensorOptions& options, const char* fn) {
  for (double v : values) {
    if (!std::isfinite(v))
      throw InputError(std::string(fn) + ": the accumulated cost overflowed (costs too large for double)");
  }
  return at::tensor(values, at::TensorOptions().dtype(at::kDouble)).to(options.dtype());
}

// Sizes of one cost matrix and of its working memory. R is (m+1) x (n+1); P (the
// soft-argmin probabilities of the diagonal, up and left predecessors) and G
// (dValue/dR) are (m+2) x (n+2), so that the backward needs no bounds tests: the
// padding row m+1 and column n+1 hold zeros, except the seed G[m+1][n+1] = 1
// with P[m+1][n+1] = (1, 0, 0), which makes G[m][n] = 1.
struct Dims {
  int64_t m, n;
  int64_t rs() const { return n + 1; }
  int64_t ps() const { return n + 2; }
  int64_t p_size() const { return 3 * (m + 2) * (n + 2); }
  int64_t g_size() const { return (m + 2) * (n + 2); }
};

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
void run_blocks(Dims dm, bool wavefront, bool reverse, const F& block) {
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
    at::parallel_for(lo, hi + 1, 1, [&](int64_t begin, int64_t end) {
      for (int64_t ti = begin; ti < end; ++ti) tile(ti, d - ti);
    });
  }
}

// Soft-DTW of one cost matrix; fills P (when not null) for the backward.
template <typename T>
double item_forward(const T* D, Dims dm, double gamma, double* P, bool wavefront) {
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

// dValue/dR from the probabilities: G[i][j] for 1 <= i <= m, 1 <= j <= n is
// dValue/dD[i-1][j-1] (stride dm.ps()).
std::unique_ptr<double[]> item_backward(const double* P, Dims dm, bool wavefront) {
  std::unique_ptr<double[]> G(new double[dm.g_size()]);
  const int64_t ps = dm.ps();
  std::fill(G.get() + (dm.m + 1) * ps, G.get() + (dm.m + 2) * ps, 0.0);
  for (int64_t i = 0; i <= dm.m; ++i) G[i * ps + dm.n + 1] = 0.0;
  G[(dm.m + 1) * ps + dm.n + 1] = 1.0;
  run_blocks(dm, wavefront, true,
             [&](int64_t i0, int64_t i1, int64_t j0, int64_t j1) { backward_block(dm, P, G.get(), i0, i1, j0, j1); });
  return G;
}

// How B items of `cells` cells each are spread over threads.
struct Plan {
  bool batch_parallel = false;
  int64_t grain = 1;
  bool wavefront = false;  // inside each item, for matrices with both sides >= kWavefrontMinSide
  bool wavefront_for(Dims dm) const { return wavefront && std::min(dm.m, dm.n) >= kWavefrontMinSide; }
};

Plan make_plan(int64_t B, int64_t cells, int64_t min_side) {
  Plan plan;
  const int64_t threads = at::get_num_threads();
  if (threads <= 1 || B * cells < kMinParallelCells) return plan;
  if (B < threads && min_side >= kWavefrontMinSide) {
    plan.wavefront = true;
  } else if (B > 1) {
    plan.batch_parallel = true;
    plan.grain = std::max<int64_t>(1, kMinParallelCells / std::max<int64_t>(cells, 1));
  }
  return plan;
}

template <typename F>
void for_each_item(int64_t B, const Plan& plan, const F& item) {
  if (plan.batch_parallel) {
    at::parallel_for(0, B, plan.grain, [&](int64_t begin, int64_t end) {
      for (int64_t b = begin; b < end; ++b) item(b);
    });
  } else {
    for (int64_t b = 0; b < B; ++b) item(b);
  }
}

// ---- soft-DTW of cost matrices ----

class SoftDtwFunction : public torch::autograd::Function<SoftDtwFunction> {
 public:
  // Values [B] of the validated, contiguous costs [B, m, n]; P [B, p_size] when wanted.
  static at::Tensor run(const at::Tensor& cost, double gamma, at::Tensor* probs) {
    const int64_t B = cost.size(0);
    const Dims dm{cost.size(1), cost.size(2)};
    const Plan plan = make_plan(B, dm.m * dm.n, std::min(dm.m, dm.n));
    std::vector<double> values(B);
    double* pbase = nullptr;
    if (probs) {
      *probs = at::empty({B, dm.p_size()}, at::TensorOptions().dtype(at::kDouble));
      pbase = probs->data_ptr<double>();
    }
    AT_DISPATCH_FLOATING_TYPES(cost.scalar_type(), "soft_dtw_forward", [&] {
      const scalar_t* dbase = cost.data_ptr<scalar_t>();
      for_each_item(B, plan, [&](int64_t b) {
        values[b] = item_forward(dbase + b * dm.m * dm.n, dm, gamma, pbase ? pbase + b * dm.p_size() : nullptr,
                                 plan.wavefront_for(dm));
      });
    });
    return checked_values(values, cost.options(), "soft_dtw");
  }

  static at::Tensor forward(torch::autograd::AutogradContext* ctx, const at::Tensor& cost, double gamma) {
    at::Tensor probs;
    at::Tensor out = run(cost, gamma, &probs);
    ctx->saved_data["probs"] = probs;
    ctx->saved_data["m"] = cost.size(1);
    ctx->saved_data["n"] = cost.size(2);
    return out;
  }

  static torch::autograd::variable_list backward(torch::autograd::AutogradContext* ctx,
                                                 torch::autograd::variable_list grad_outputs) {
    at::Tensor grad = grad_outputs[0].to(at::kDouble).contiguous();
    at::Tensor probs = ctx->saved_data["probs"].toTensor();
    const Dims dm{ctx->saved_data["m"].toInt(), ctx->saved_data["n"].toInt()};
    const int64_t B = probs.size(0);
    const Plan plan = make_plan(B, dm.m * dm.n, std::min(dm.m, dm.n));
    at::Tensor E = at::empty({B, dm.m, dm.n}, grad_outputs[0].options());
    const double* pbase = probs.data_ptr<double>();
    const double* g = grad.data_ptr<double>();
    AT_DISPATCH_FLOATING_TYPES(E.scalar_type(), "soft_dtw_backward", [&] {
      scalar_t* ebase = E.data_ptr<scalar_t>();
      for_each_item(B, plan, [&](int64_t b) {
        auto G = item_backward(pbase + b * dm.p_size(), dm, plan.wavefront_for(dm));
        scalar_t* e = ebase + b * dm.m * dm.n;
        for (int64_t i = 0; i < dm.m; ++i)
          for (int64_t j = 0; j < dm.n; ++j)
            e[i * dm.n + j] = static_cast<scalar_t>(G[(i + 1) * dm.ps() + j + 1] * g[b]);
      });
    });
    return {E, at::Tensor()};
  }
};

at::Tensor soft_dtw_checked(const at::Tensor& cost, double gamma) {
  if (cost.size(0) == 0) return at::zeros({0}, cost.options());
  if (at::GradMode::is_enabled() && cost.requires_grad()) return SoftDtwFunction::apply(cost, gamma);
  return SoftDtwFunction::run(cost, gamma, nullptr);
}

// ---- soft-DTW and its divergence on sequences, with the squared Euclidean cost ----

// One cost matrix of a sequence pair: D[i][j] = |a_i - b_j|^2 = |a_i|^2 + |b_j|^2 -
// 2 a_i.b_j (a [m, d], b [n, d]), through an Eigen matrix product (single-threaded):
// 10x faster than the explicit differences, and in double the cancellation error
// (~1e-16 (|a_i|^2 + |b_j|^2)) is far below any useful gamma. Clamped at 0. Equal
// inputs give bitwise equal matrices, so the divergence stays exactly 0 at x = y.
void pair_cost(const double* a, int64_t m, const double* b, int64_t n, int64_t d, double* D) {
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const Eigen::Map<const RowMajor> A(a, m, d), Bm(b, n, d);
  Eigen::Map<RowMajor> Dm(D, m, n);
  Dm.noalias() = A * Bm.transpose();
  const Eigen::VectorXd na = A.rowwise().squaredNorm(), nb = Bm.rowwise().squaredNorm();
  for (int64_t i = 0; i < m; ++i)
    for (int64_t j = 0; j < n; ++j) D[i * n + j] = std::max(0.0, (na[i] + nb[j]) - 2.0 * D[i * n + j]);
}

// Adds w dValue/da and w dValue/db for the pair's alignment E (G of
// item_backward): with dD[i][j]/da_i = 2 (a_i - b_j) = -dD[i][j]/db_j,
//   ga_i += 2 w (sum_j E_ij a_i - sum_j E_ij b_j),  gb_j += 2 w (sum_i E_ij b_j - sum_i E_ij a_i).
// Rows of a, then rows of b, each summed in a fixed order, so that the result
// does not depend on how the rows are split over threads; ga and gb may alias (a = b).
void pair_grad(const double* G, Dims dm, const double* a, const double* b, int64_t d, double w, double* ga, double* gb,
               bool parallel) {
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
    at::parallel_for(0, dm.m, 1, rows_of_a);
    at::parallel_for(0, dm.n, 1, rows_of_b);
  } else {
    rows_of_a(0, dm.m);
    rows_of_b(0, dm.n);
  }
}

enum class SequenceMode : int64_t { kValue = 0, kDivergence = 1 };

// A pair of the computation: sdtw(first, second) with weight w.
struct PairSpec {
  bool first_is_x, second_is_x;
  double weight;
  Dims dm;
};

std::vector<PairSpec> pair_specs(SequenceMode mode, int64_t m, int64_t n) {
  std::vector<PairSpec> pairs = {{true, false, 1.0, {m, n}}};
  if (mode == SequenceMode::kDivergence) {
    pairs.push_back({true, true, -0.5, {m, m}});
    pairs.push_back({false, false, -0.5, {n, n}});
  }
  return pairs;
}

// The probabilities of a pair are kept when one of its sides needs a gradient.
bool pair_needs_grad(const PairSpec& p, bool need_x, bool need_y) {
  const bool uses_x = p.first_is_x || p.second_is_x, uses_y = !p.first_is_x || !p.second_is_x;
  return (uses_x && need_x) || (uses_y && need_y);
}

// The batch size of x [Bx, ...] and y [By, ...] where Bx and By are equal or one of them is 1.
int64_t batch_of(const at::Tensor& x, const at::Tensor& y) { return x.size(0) == 1 ? y.size(0) : x.size(0); }

// Item b of a [batch, size] buffer in double; a batch of 1 is broadcast.
template <typename T>
std::vector<double> item_in_double(const T* data, int64_t batch, int64_t b, int64_t size) {
  const T* item = data + (batch == 1 ? 0 : b) * size;
  return std::vector<double>(item, item + size);
}

class SoftDtwSequenceFunction : public torch::autograd::Function<SoftDtwSequenceFunction> {
 public:
  // x [Bx, m, d], y [By, n, d] validated and contiguous, Bx and By equal or 1;
  // probs: one tensor per pair (undefined when not needed), or null for no grad.
  static at::Tensor run(const at::Tensor& x, const at::Tensor& y, double gamma, SequenceMode mode, bool need_x,
                        bool need_y, std::vector<at::Tensor>* probs) {
    const int64_t B = batch_of(x, y), m = x.size(1), n = y.size(1), d = x.size(2);
    const std::vector<PairSpec> pairs = pair_specs(mode, m, n);
    int64_t cells = 0, min_side = 0;
    for (const PairSpec& p : pairs) {
      cells += p.dm.m * p.dm.n;
      min_side = std::max(min_side, std::min(p.dm.m, p.dm.n));
    }
    const Plan plan = make_plan(B, cells, min_side);
    std::vector<double*> pbase(pairs.size(), nullptr);
    if (probs) {
      probs->assign(pairs.size(), at::Tensor());
      for (size_t k = 0; k < pairs.size(); ++k)
        if (pair_needs_grad(pairs[k], need_x, need_y)) {
          (*probs)[k] = at::empty({B, pairs[k].dm.p_size()}, at::TensorOptions().dtype(at::kDouble));
          pbase[k] = (*probs)[k].data_ptr<double>();
        }
    }
    std::vector<double> values(B, 0.0);
    AT_DISPATCH_FLOATING_TYPES(x.scalar_type(), "soft_dtw_sequences_forward", [&] {
      const scalar_t* xb = x.data_ptr<scalar_t>();
      const scalar_t* yb = y.data_ptr<scalar_t>();
      for_each_item(B, plan, [&](int64_t b) {
        const std::vector<double> xd = item_in_double(xb, x.size(0), b, m * d);
        const std::vector<double> yd = item_in_double(yb, y.size(0), b, n * d);
        double total = 0.0;
        for (size_t k = 0; k < pairs.size(); ++k) {
          const PairSpec& p = pairs[k];
          const bool wavefront = plan.wavefront_for(p.dm);
          std::unique_ptr<double[]> D(new double[p.dm.m * p.dm.n]);
          pair_cost((p.first_is_x ? xd : yd).data(), p.dm.m, (p.second_is_x ? xd : yd).data(), p.dm.n, d, D.get());
          const double v = item_forward(D.get(), p.dm, gamma, pbase[k] ? pbase[k] + b * p.dm.p_size() : nullptr,
                                        wavefront);
          total += p.weight * v;
        }
        values[b] = total;
      });
    });
    return checked_values(values, x.options(), "soft_dtw_sequences");
  }

  static at::Tensor forward(torch::autograd::AutogradContext* ctx, const at::Tensor& x, const at::Tensor& y,
                            double gamma, int64_t mode, bool need_x, bool need_y) {
    std::vector<at::Tensor> probs;
    at::Tensor out = run(x, y, gamma, static_cast<SequenceMode>(mode), need_x, need_y, &probs);
    ctx->save_for_backward({x, y});
    for (size_t k = 0; k < probs.size(); ++k) ctx->saved_data["probs" + std::to_string(k)] = probs[k];
    ctx->saved_data["mode"] = mode;
    ctx->saved_data["need_x"] = need_x;
    ctx->saved_data["need_y"] = need_y;
    return out;
  }

  static torch::autograd::variable_list backward(torch::autograd::AutogradContext* ctx,
                                                 torch::autograd::variable_list grad_outputs) {
    const auto saved = ctx->get_saved_variables();
    const at::Tensor& x = saved[0];
    const at::Tensor& y = saved[1];
    const auto mode = static_cast<SequenceMode>(ctx->saved_data["mode"].toInt());
    const bool need_x = ctx->saved_data["need_x"].toBool(), need_y = ctx->saved_data["need_y"].toBool();
    const int64_t B = batch_of(x, y), m = x.size(1), n = y.size(1), d = x.size(2);
    const std::vector<PairSpec> pairs = pair_specs(mode, m, n);
    std::vector<const double*> pbase(pairs.size(), nullptr);
    std::vector<at::Tensor> probs(pairs.size());
    int64_t cells = 0, min_side = 0;
    for (size_t k = 0; k < pairs.size(); ++k) {
      cells += pairs[k].dm.m * pairs[k].dm.n;
      min_side = std::max(min_side, std::min(pairs[k].dm.m, pairs[k].dm.n));
      const at::IValue& v = ctx->saved_data["probs" + std::to_string(k)];
      if (v.isTensor() && v.toTensor().defined()) {
        probs[k] = v.toTensor();
        pbase[k] = probs[k].data_ptr<double>();
      }
    }
    const Plan plan = make_plan(B, cells, min_side);
    at::Tensor grad = grad_outputs[0].to(at::kDouble).contiguous();
    const double* g = grad.data_ptr<double>();
    // Per-item gradients in double, summed over the batch afterwards where an
    // input was broadcast (batch 1).
    std::vector<double> gx(need_x ? B * m * d : 0, 0.0), gy(need_y ? B * n * d : 0, 0.0);
    AT_DISPATCH_FLOATING_TYPES(x.scalar_type(), "soft_dtw_sequences_backward", [&] {
      const scalar_t* xb = x.data_ptr<scalar_t>();
      const scalar_t* yb = y.data_ptr<scalar_t>();
      for_each_item(B, plan, [&](int64_t b) {
        const std::vector<double> xd = item_in_double(xb, x.size(0), b, m * d);
        const std::vector<double> yd = item_in_double(yb, y.size(0), b, n * d);
        std::vector<double> scratch_x(need_x ? 0 : m * d), scratch_y(need_y ? 0 : n * d);
        double* gxb = need_x ? gx.data() + b * m * d : scratch_x.data();
        double* gyb = need_y ? gy.data() + b * n * d : scratch_y.data();
        for (size_t k = 0; k < pairs.size(); ++k) {
          if (!pbase[k]) continue;
          const PairSpec& p = pairs[k];
          const bool wavefront = plan.wavefront_for(p.dm);
          auto G = item_backward(pbase[k] + b * p.dm.p_size(), p.dm, wavefront);
          pair_grad(G.get(), p.dm, (p.first_is_x ? xd : yd).data(), (p.second_is_x ? xd : yd).data(), d,
                    p.weight * g[b], p.first_is_x ? gxb : gyb, p.second_is_x ? gxb : gyb, wavefront);
        }
      });
    });
    return {need_x ? gradient_of_input(gx, x, B) : at::Tensor(), need_y ? gradient_of_input(gy, y, B) : at::Tensor(),
            at::Tensor(), at::Tensor(), at::Tensor(), at::Tensor()};
  }

 private:
  // The gradient of `input` [B or 1, len, d] from the per-item gradients
  // `full` [B, len, d] (double): converted to the input's dtype, and summed
  // over the batch in item order where the input was broadcast (batch 1).
  static at::Tensor gradient_of_input(const std::vector<double>& full, const at::Tensor& input, int64_t B) {
    at::Tensor out = at::empty(input.sizes(), input.options().requires_grad(false));  // every element is written
    AT_DISPATCH_FLOATING_TYPES(input.scalar_type(), "soft_dtw_sequences_grad", [&] {
      scalar_t* o = out.data_ptr<scalar_t>();
      const int64_t item = input.size(1) * input.size(2);
      if (input.size(0) == B) {
        for (int64_t k = 0; k < B * item; ++k) o[k] = static_cast<scalar_t>(full[k]);
      } else {
        std::vector<double> sum(item, 0.0);
        for (int64_t b = 0; b < B; ++b)
          for (int64_t k = 0; k < item; ++k) sum[k] += full[b * item + k];
        for (int64_t k = 0; k < item; ++k) o[k] = static_cast<scalar_t>(sum[k]);
      }
    });
    return out;
  }
};

// Validates x [Bx, m, d] and y [By, n, d] (Bx and By equal or one of them 1);
// returns contiguous tensors.
std::pair<at::Tensor, at::Tensor> check_sequences(const at::Tensor& x, const at::Tensor& y, const char* fn) {
  require_float_cpu(x, fn, "x");
  require_float_cpu(y, fn, "y");
  if (x.dim() != 3 || y.dim() != 3)
    throw InputError(std::string(fn) + ": x and y must have shape [B, frames, d], got " + shape_string(x) + " and " +
                     shape_string(y));
  if (x.scalar_type() != y.scalar_type()) throw InputError(std::string(fn) + ": x and y must have the same dtype");
  if (x.size(2) != y.size(2))
    throw InputError(std::string(fn) + ": x and y must have the same feature size d, got " + shape_string(x) +
                     " and " + shape_string(y));
  if (x.size(1) < 1 || y.size(1) < 1)
    throw InputError(std::string(fn) + ": sequences must have at least one frame, got " + shape_string(x) + " and " +
                     shape_string(y));
  if (x.size(2) < 1) throw InputError(std::string(fn) + ": feature size d must be at least 1");
  if (x.size(0) != y.size(0) && x.size(0) != 1 && y.size(0) != 1)
    throw InputError(std::string(fn) + ": batch sizes differ (" + shape_string(x) + " vs " + shape_string(y) +
                     "); they must be equal or one of them 1");
  at::Tensor xc = x.contiguous(), yc = y.contiguous();
  require_finite(xc, fn, "x");
  require_finite(yc, fn, "y");
  return {xc, yc};
}

at::Tensor sequences(const at::Tensor& x, const at::Tensor& y, double gamma, SequenceMode mode, const char* fn) {
  require_gamma(gamma, fn);
  auto xy = check_sequences(x, y, fn);
  if (batch_of(x, y) == 0) return at::zeros({0}, x.options());
  const bool grad = at::GradMode::is_enabled();
  const bool need_x = grad && x.requires_grad(), need_y = grad && y.requires_grad();
  if (need_x || need_y)
    return SoftDtwSequenceFunction::apply(xy.first, xy.second, gamma, static_cast<int64_t>(mode), need_x, need_y);
  return SoftDtwSequenceFunction::run(xy.first, xy.second, gamma, mode, false, false, nullptr);
}

}  // namespace

at::Tensor soft_dtw(const at::Tensor& cost, double gamma) {
  constexpr const char* fn = "soft_dtw";
  require_float_cpu(cost, fn, "cost");
  require_gamma(gamma, fn);
  if (cost.dim() != 2 && cost.dim() != 3)
    throw InputError(std::string(fn) + ": cost must have shape [m, n] or [B, m, n], got " + shape_string(cost));
  if (cost.size(-1) < 1 || cost.size(-2) < 1)
    throw InputError(std::string(fn) + ": sequences must have at least one frame, cost has shape " +
                     shape_string(cost));
  at::Tensor c = cost.contiguous();
  require_finite(c, fn, "cost");
  if (c.dim() == 2) return soft_dtw_checked(c.unsqueeze(0), gamma).squeeze(0);
  return soft_dtw_checked(c, gamma);
}

at::Tensor squared_euclidean_cost(const at::Tensor& x, const at::Tensor& y) {
  auto xy = check_sequences(x, y, "squared_euclidean_cost");
  const int64_t B = batch_of(x, y);
  return (xy.first.expand({B, x.size(1), x.size(2)}).unsqueeze(2) - xy.second.expand({B, y.size(1), y.size(2)}).unsqueeze(1))
      .pow(2)
      .sum(-1);
}

at::Tensor soft_dtw_sequences(const at::Tensor& x, const at::Tensor& y, double gamma) {
  return sequences(x, y, gamma, SequenceMode::kValue, "soft_dtw_sequences");
}

at::Tensor soft_dtw_divergence(const at::Tensor& x, const at::Tensor& y, double gamma) {
  return sequences(x, y, gamma, SequenceMode::kDivergence, "soft_dtw_divergence");
}

}  // namespace mf
