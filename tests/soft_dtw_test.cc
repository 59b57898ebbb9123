#include "tasks/reference/soft_dtw.h"

#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <gtest/gtest.h>
#include <torch/csrc/autograd/autograd.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <tuple>
#include <vector>

#include "prior/motion/errors.h"
#include "tasks/renav/soft_dtw_kernels.h"

namespace mf {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
const auto kF64 = at::TensorOptions().dtype(at::kDouble);

// Restores the intra-op thread count on scope exit.
struct ThreadCount {
  int saved = at::get_num_threads();
  explicit ThreadCount(int n) { at::set_num_threads(n); }
  ~ThreadCount() { at::set_num_threads(saved); }
};

double softmin(double a, double b, double c, double g) {
  return -g * std::log(std::exp(-a / g) + std::exp(-b / g) + std::exp(-c / g));
}

// Value and dValue/dcost of soft_dtw through autograd.
std::pair<at::Tensor, at::Tensor> value_and_grad(const at::Tensor& cost, double gamma) {
  at::Tensor c = cost.detach().clone().requires_grad_(true);
  at::Tensor v = soft_dtw(c, gamma);
  v.sum().backward();
  return {v.detach(), c.grad()};
}

// Plain dynamic-programming DTW table (min over monotone alignments of summed costs).
std::vector<std::vector<double>> hard_dtw_table(const at::Tensor& cost) {
  const int64_t m = cost.size(0), n = cost.size(1);
  auto D = cost.accessor<double, 2>();
  std::vector<std::vector<double>> R(m + 1, std::vector<double>(n + 1, kInf));
  R[0][0] = 0;
  for (int64_t i = 1; i <= m; ++i)
    for (int64_t j = 1; j <= n; ++j)
      R[i][j] = D[i - 1][j - 1] + std::min({R[i - 1][j - 1], R[i - 1][j], R[i][j - 1]});
  return R;
}

// The hard DTW path as a 0/1 matrix (backtracking the DP).
at::Tensor hard_dtw_path(const at::Tensor& cost) {
  const int64_t m = cost.size(0), n = cost.size(1);
  auto R = hard_dtw_table(cost);
  at::Tensor path = at::zeros({m, n}, kF64);
  int64_t i = m, j = n;
  while (i >= 1 && j >= 1) {
    path[i - 1][j - 1] = 1.0;
    const double a = R[i - 1][j - 1], b = R[i - 1][j], c = R[i][j - 1];
    if (a <= b && a <= c) {
      --i;
      --j;
    } else if (b <= c) {
      --i;
    } else {
      --j;
    }
  }
  return path;
}

// An independent soft-DTW: forward with the full R matrix (log-sum-exp shifted by
// the max of -R/gamma), and the classic backward of Cuturi and Blondel (2017,
// Algorithm 2) from exponentials of R differences. Returns the value and E.
std::pair<double, at::Tensor> reference_soft_dtw(const at::Tensor& cost, double g) {
  const int64_t m = cost.size(0), n = cost.size(1);
  auto D = cost.accessor<double, 2>();
  std::vector<double> R((m + 2) * (n + 2), -kInf), Dp((m + 2) * (n + 2), 0.0), E((m + 2) * (n + 2), 0.0);
  auto at2 = [n](int64_t i, int64_t j) { return i * (n + 2) + j; };
  for (int64_t i = 0; i <= m; ++i) R[at2(i, 0)] = kInf;
  for (int64_t j = 0; j <= n; ++j) R[at2(0, j)] = kInf;
  R[at2(0, 0)] = 0;
  for (int64_t i = 1; i <= m; ++i)
    for (int64_t j = 1; j <= n; ++j) {
      Dp[at2(i, j)] = D[i - 1][j - 1];
      const double a = -R[at2(i - 1, j - 1)] / g, b = -R[at2(i - 1, j)] / g, c = -R[at2(i, j - 1)] / g;
      const double mx = std::max({a, b, c});
      R[at2(i, j)] = D[i - 1][j - 1] - g * (mx + std::log(std::exp(a - mx) + std::exp(b - mx) + std::exp(c - mx)));
    }
  const double value = R[at2(m, n)];
  R[at2(m + 1, n + 1)] = value;
  E[at2(m + 1, n + 1)] = 1.0;
  for (int64_t i = m; i >= 1; --i)
    for (int64_t j = n; j >= 1; --j) {
      const double r = R[at2(i, j)];
      const double a = std::exp((R[at2(i + 1, j)] - r - Dp[at2(i + 1, j)]) / g);
      const double b = std::exp((R[at2(i, j + 1)] - r - Dp[at2(i, j + 1)]) / g);
      const double c = std::exp((R[at2(i + 1, j + 1)] - r - Dp[at2(i + 1, j + 1)]) / g);
      E[at2(i, j)] = E[at2(i + 1, j)] * a + E[at2(i, j + 1)] * b + E[at2(i + 1, j + 1)] * c;
    }
  at::Tensor out = at::empty({m, n}, kF64);
  auto o = out.accessor<double, 2>();
  for (int64_t i = 1; i <= m; ++i)
    for (int64_t j = 1; j <= n; ++j) o[i - 1][j - 1] = E[at2(i, j)];
  return {value, out};
}

// Central finite difference of f (a scalar function) with respect to element k
// of the flattened tensor t (double, contiguous), restoring t afterwards.
double central_difference(const std::function<double()>& f, at::Tensor& t, int64_t k, double h) {
  double* p = t.data_ptr<double>() + k;
  const double saved = *p;
  *p = saved + h;
  const double plus = f();
  *p = saved - h;
  const double minus = f();
  *p = saved;
  return (plus - minus) / (2 * h);
}

TEST(SoftDtw, OneByOneIsTheCost) {
  at::Tensor D = at::full({1, 1}, 0.7, kF64);
  auto vg = value_and_grad(D, 0.5);
  EXPECT_DOUBLE_EQ(vg.first.item<double>(), 0.7);
  EXPECT_DOUBLE_EQ(vg.second[0][0].item<double>(), 1.0);
  // float input: float result
  at::Tensor v = soft_dtw(D.to(at::kFloat), 0.5);
  EXPECT_EQ(v.scalar_type(), at::kFloat);
  EXPECT_EQ(v.dim(), 0);
  EXPECT_FLOAT_EQ(v.item<float>(), 0.7f);
}

TEST(SoftDtw, OneByTwoAndTwoByOneSumTheCosts) {
  // R[1,1] = D00 + softmin(0, inf, inf) = D00; R[1,2] = D01 + softmin(inf, inf, R[1,1]).
  at::Tensor D = at::tensor({0.3, 1.9}, kF64).reshape({1, 2});
  for (const at::Tensor& c : {D, D.t().contiguous()}) {
    auto vg = value_and_grad(c, 0.2);
    EXPECT_NEAR(vg.first.item<double>(), 0.3 + 1.9, 1e-15);
    EXPECT_TRUE(at::allclose(vg.second, at::ones_like(c), 0, 1e-15));
  }
}

TEST(SoftDtw, TwoByTwoByHand) {
  const double d00 = 0.4, d01 = 0.25, d10 = 0.9, d11 = 0.1;
  at::Tensor D = at::tensor({d00, d01, d10, d11}, kF64).reshape({2, 2});
  for (double g : {0.05, 0.3, 2.0}) {
    const double r11 = d00, r12 = d00 + d01, r21 = d00 + d10;
    const double r22 = d11 + softmin(r11, r12, r21, g);
    // Probabilities of the three predecessors of (2, 2).
    const double s = std::exp(-r11 / g) + std::exp(-r12 / g) + std::exp(-r21 / g);
    const double p_up = std::exp(-r12 / g) / s, p_left = std::exp(-r21 / g) / s;
    auto vg = value_and_grad(D, g);
    EXPECT_NEAR(vg.first.item<double>(), r22, 1e-14) << "gamma " << g;
    auto E = vg.second.accessor<double, 2>();
    EXPECT_NEAR(E[0][0], 1.0, 1e-14);
    EXPECT_NEAR(E[1][1], 1.0, 1e-14);
    EXPECT_NEAR(E[0][1], p_up, 1e-14);    // R[1,2] uses D[0][1]
    EXPECT_NEAR(E[1][0], p_left, 1e-14);  // R[2,1] uses D[1][0]
  }
}

TEST(SoftDtw, LengthOneSequences) {
  at::manual_seed(1);
  at::Tensor x = at::randn({1, 1, 3}, kF64), y = at::randn({1, 5, 3}, kF64);
  // Only one alignment: every frame of y against the single frame of x.
  const double expected = (x - y).pow(2).sum().item<double>();
  at::Tensor xg = x.clone().requires_grad_(true);
  at::Tensor v = soft_dtw_sequences(xg, y, 0.1);
  ASSERT_EQ(v.sizes(), at::IntArrayRef({1}));
  EXPECT_NEAR(v.item<double>(), expected, 1e-12);
  v.sum().backward();
  EXPECT_TRUE(at::allclose(xg.grad(), (2 * (x - y)).sum(1, true), 1e-12, 1e-12));
  // Two single frames: the divergence is the squared distance.
  at::Tensor y1 = y.slice(1, 0, 1);
  EXPECT_NEAR(soft_dtw_divergence(x, y1, 0.1).item<double>(), (x - y1).pow(2).sum().item<double>(), 1e-12);
  EXPECT_EQ(soft_dtw_divergence(x, x, 0.1).item<double>(), 0.0);
}

TEST(SoftDtw, SmallGammaApproachesHardDtw) {
  at::manual_seed(2);
  at::Tensor D = at::rand({7, 9}, kF64);
  const double hard = hard_dtw_table(D)[7][9];
  for (double g : {1.0, 0.1, 0.01, 1e-3, 1e-5}) {
    const double v = soft_dtw(D, g).item<double>();
    EXPECT_LE(v, hard + 1e-12) << "gamma " << g;
    EXPECT_GE(v, hard - g * std::log(3.0) * (7 + 9 - 1)) << "gamma " << g;
  }
  // The expected alignment becomes the hard path.
  auto vg = value_and_grad(D, 1e-5);
  EXPECT_LT((vg.second - hard_dtw_path(D)).abs().max().item<double>(), 1e-6);
  // A gamma so small that 1/gamma overflows, with ties everywhere (all costs 0).
  auto ties = value_and_grad(at::zeros({3, 4}, kF64), 1e-320);
  EXPECT_LE(ties.first.item<double>(), 0.0);  // -gamma log(number of paths), a denormal
  EXPECT_GT(ties.first.item<double>(), -1e-300);
  EXPECT_TRUE(at::isfinite(ties.second).all().item<bool>());
  EXPECT_GE(ties.second.min().item<double>(), 0.0);
  EXPECT_LE(ties.second.max().item<double>(), 1.0 + 1e-12);
  EXPECT_EQ(ties.second[0][0].item<double>(), 1.0);
  EXPECT_EQ(ties.second[2][3].item<double>(), 1.0);
  EXPECT_EQ(soft_dtw(D, 1e-320).item<double>(), hard);
}

TEST(SoftDtw, MatchesIndependentImplementation) {
  at::manual_seed(3);
  for (auto mn : {std::pair<int, int>{1, 6}, {6, 1}, {5, 8}, {13, 11}}) {
    at::Tensor D = at::rand({mn.first, mn.second}, kF64) * 3;
    for (double g : {0.01, 0.1, 1.0}) {
      auto ours = value_and_grad(D, g);
      auto ref = reference_soft_dtw(D, g);
      EXPECT_NEAR(ours.first.item<double>(), ref.first, 1e-12 * std::max(1.0, std::abs(ref.first)));
      EXPECT_LT((ours.second - ref.second).abs().max().item<double>(), 1e-12);
    }
  }
}

TEST(SoftDtw, GradientMatchesFiniteDifferences) {
  at::manual_seed(4);
  at::Tensor D = at::rand({2, 4, 5}, kF64) * 2;
  for (double g : {0.1, 1.0}) {
    auto vg = value_and_grad(D, g);
    at::Tensor Dc = D.clone();
    for (int64_t b = 0; b < 2; ++b)
      for (int64_t k = 0; k < 20; ++k) {
        auto f = [&] { return soft_dtw(Dc, g)[b].item<double>(); };
        const double fd = central_difference(f, Dc, b * 20 + k, 1e-5);
        const double an = vg.second.reshape(-1)[b * 20 + k].item<double>();
        EXPECT_NEAR(an, fd, 1e-6 * std::max(1.0, std::abs(fd))) << "gamma " << g << " b " << b << " k " << k;
      }
  }
}

TEST(SoftDtw, DivergenceGradientMatchesFiniteDifferences) {
  at::manual_seed(5);
  at::Tensor x = at::randn({2, 4, 3}, kF64), y = at::randn({2, 5, 3}, kF64);
  for (double g : {0.1, 1.0}) {
    at::Tensor xg = x.clone().requires_grad_(true), yg = y.clone().requires_grad_(true);
    soft_dtw_divergence(xg, yg, g).sum().backward();
    for (bool is_x : {true, false}) {
      at::Tensor t = (is_x ? x : y).clone();
      at::Tensor grad = (is_x ? xg : yg).grad().reshape(-1);
      auto f = [&] { return soft_dtw_divergence(is_x ? t : x, is_x ? y : t, g).sum().item<double>(); };
      for (int64_t k = 0; k < t.numel(); ++k) {
        const double fd = central_difference(f, t, k, 1e-5);
        EXPECT_NEAR(grad[k].item<double>(), fd, 1e-6 * std::max(1.0, std::abs(fd)))
            << (is_x ? "x" : "y") << " gamma " << g << " k " << k;
      }
    }
  }
}

TEST(SoftDtw, DivergenceIsZeroAtEqualInputsAndNonNegative) {
  at::manual_seed(6);
  at::Tensor x = at::randn({4, 6, 3}, kF64);
  for (double g : {0.01, 0.1, 1.0}) {
    at::Tensor xg = x.clone().requires_grad_(true);
    at::Tensor d = soft_dtw_divergence(xg, x, g);
    EXPECT_TRUE(at::equal(d.detach(), at::zeros({4}, kF64))) << d;
    d.sum().backward();  // a minimum: zero gradient
    EXPECT_LT(xg.grad().abs().max().item<double>(), 1e-10);
    at::Tensor xf = x.to(at::kFloat);
    EXPECT_TRUE(at::equal(soft_dtw_divergence(xf, xf, g), at::zeros({4}, at::kFloat)));
  }
  for (auto mn : {std::pair<int, int>{6, 6}, {5, 9}, {1, 4}}) {
    at::Tensor a = at::randn({16, mn.first, 2}, kF64), b = at::randn({16, mn.second, 2}, kF64);
    for (double g : {0.01, 0.1, 1.0, 10.0}) {
      at::Tensor d = soft_dtw_divergence(a, b, g);
      EXPECT_GE(d.min().item<double>(), 0.0) << "gamma " << g;
      EXPECT_TRUE(at::allclose(d, soft_dtw_divergence(b, a, g), 1e-12, 1e-12));  // symmetric
    }
  }
  // A small perturbation gives a small positive divergence.
  at::Tensor y = x + 1e-3 * at::randn_like(x);
  at::Tensor d = soft_dtw_divergence(x, y, 0.1);
  EXPECT_GT(d.min().item<double>(), 0.0);
  EXPECT_LT(d.max().item<double>(), 1e-3);
}

TEST(SoftDtw, BatchedEqualsPerItemAtAnyThreadCount) {
  at::manual_seed(7);
  // [6, 120, 110]: enough cells for the batch to run in parallel at 2 threads.
  for (auto shape : {std::vector<int64_t>{5, 7, 6}, std::vector<int64_t>{6, 120, 110}}) {
    at::Tensor D = at::rand(shape, kF64);
    auto batched = value_and_grad(D, 0.1);
    ASSERT_EQ(batched.first.sizes(), at::IntArrayRef({shape[0]}));
    for (int64_t b = 0; b < shape[0]; ++b) {
      auto item = value_and_grad(D[b], 0.1);
      EXPECT_EQ(batched.first[b].item<double>(), item.first.item<double>());
      EXPECT_TRUE(at::equal(batched.second[b], item.second));
    }
    ThreadCount two(2);
    auto parallel = value_and_grad(D, 0.1);
    EXPECT_TRUE(at::equal(parallel.first, batched.first));
    EXPECT_TRUE(at::equal(parallel.second, batched.second));
  }
}

TEST(SoftDtw, WithoutGradGivesTheSameValue) {
  at::manual_seed(8);
  at::Tensor D = at::rand({3, 9, 4}, kF64);
  at::Tensor with_grad = value_and_grad(D, 0.1).first;
  EXPECT_TRUE(at::equal(soft_dtw(D, 0.1), with_grad));
  at::NoGradGuard no_grad;
  EXPECT_TRUE(at::equal(soft_dtw(D.clone().requires_grad_(true), 0.1), with_grad));
}

TEST(SoftDtw, CostAndBroadcasting) {
  at::manual_seed(9);
  at::Tensor x = at::randn({1, 4, 3}, kF64), y = at::randn({3, 5, 3}, kF64);
  at::Tensor C = squared_euclidean_cost(x, y);
  ASSERT_EQ(C.sizes(), at::IntArrayRef({3, 4, 5}));
  EXPECT_NEAR(C[2][1][3].item<double>(), (x[0][1] - y[2][3]).pow(2).sum().item<double>(), 1e-14);
  at::Tensor d = soft_dtw_divergence(x, y, 0.1);
  ASSERT_EQ(d.sizes(), at::IntArrayRef({3}));
  for (int64_t b = 0; b < 3; ++b)
    EXPECT_EQ(d[b].item<double>(), soft_dtw_divergence(x, y.slice(0, b, b + 1), 0.1).item<double>());
  at::Tensor s = soft_dtw_sequences(y, x, 0.1);
  ASSERT_EQ(s.sizes(), at::IntArrayRef({3}));
  EXPECT_NEAR(s[1].item<double>(), soft_dtw(squared_euclidean_cost(y.slice(0, 1, 2), x)[0], 0.1).item<double>(),
              1e-14);
}

// The fused sequence functions (cost computed in C++) against soft_dtw on the
// torch-op cost matrix, values and gradients, with a broadcast batch of 1.
TEST(SoftDtw, SequenceFunctionsMatchTheComposition) {
  at::manual_seed(11);
  at::Tensor x = at::randn({3, 5, 4}, kF64), y = at::randn({1, 7, 4}, kF64);
  for (bool divergence : {false, true}) {
    at::Tensor x1 = x.clone().requires_grad_(true), y1 = y.clone().requires_grad_(true);
    at::Tensor x2 = x.clone().requires_grad_(true), y2 = y.clone().requires_grad_(true);
    at::Tensor fused = divergence ? soft_dtw_divergence(x1, y1, 0.3) : soft_dtw_sequences(x1, y1, 0.3);
    at::Tensor composed = soft_dtw(squared_euclidean_cost(x2, y2), 0.3);
    if (divergence)
      composed = composed - 0.5 * soft_dtw(squared_euclidean_cost(x2, x2), 0.3) -
                 0.5 * soft_dtw(squared_euclidean_cost(y2, y2), 0.3);
    ASSERT_EQ(fused.sizes(), at::IntArrayRef({3}));
    EXPECT_TRUE(at::allclose(fused, composed, 1e-12, 1e-12));
    (fused * at::tensor({1.0, -2.0, 0.5}, kF64)).sum().backward();
    (composed * at::tensor({1.0, -2.0, 0.5}, kF64)).sum().backward();
    EXPECT_TRUE(at::allclose(x1.grad(), x2.grad(), 1e-12, 1e-12)) << "divergence " << divergence;
    ASSERT_EQ(y1.grad().sizes(), y.sizes());
    EXPECT_TRUE(at::allclose(y1.grad(), y2.grad(), 1e-12, 1e-12)) << "divergence " << divergence;
  }
  // Gradient for one side only; float inputs give float results and gradients.
  at::Tensor yf = y.to(at::kFloat).requires_grad_(true);
  at::Tensor d = soft_dtw_divergence(x.to(at::kFloat), yf, 0.3);
  EXPECT_EQ(d.scalar_type(), at::kFloat);
  d.sum().backward();
  EXPECT_EQ(yf.grad().scalar_type(), at::kFloat);
  at::Tensor yd = y.clone().requires_grad_(true);
  soft_dtw_divergence(x, yd, 0.3).sum().backward();
  EXPECT_TRUE(at::allclose(yf.grad().to(at::kDouble), yd.grad(), 1e-4, 1e-4));
}

// Sequences long enough for the tiled wavefront inside each of the three terms.
TEST(SoftDtw, LongDivergenceIsThreadCountIndependent) {
  at::manual_seed(12);
  at::Tensor x = at::randn({1, 600, 2}, kF64), y = at::randn({1, 530, 2}, kF64);
  auto run = [&] {
    at::Tensor xg = x.clone().requires_grad_(true), yg = y.clone().requires_grad_(true);
    at::Tensor d = soft_dtw_divergence(xg, yg, 0.1);
    d.sum().backward();
    return std::make_tuple(d.detach(), xg.grad(), yg.grad());
  };
  auto one = run();
  EXPECT_GT(std::get<0>(one).item<double>(), 0.0);
  ThreadCount two(2);
  auto par = run();
  EXPECT_TRUE(at::equal(std::get<0>(one), std::get<0>(par)));
  EXPECT_TRUE(at::equal(std::get<1>(one), std::get<1>(par)));
  EXPECT_TRUE(at::equal(std::get<2>(one), std::get<2>(par)));
}

// 1500 x 1300, well past the 1024 limit of the CUDA/Numba versions: the value and
// the whole expected alignment against the classic backward, a few entries
// against finite differences, and bitwise agreement of the 2-thread wavefront.
TEST(SoftDtw, LongSequences) {
  at::manual_seed(10);
  const double g = 0.1;
  at::Tensor D = at::rand({1500, 1300}, kF64);
  auto ours = value_and_grad(D, g);
  const double v = ours.first.item<double>();
  ASSERT_TRUE(std::isfinite(v));
  ASSERT_TRUE(at::isfinite(ours.second).all().item<bool>());
  auto ref = reference_soft_dtw(D, g);
  EXPECT_NEAR(v, ref.first, 1e-12 * std::abs(ref.first));
  EXPECT_LT((ours.second - ref.second).abs().max().item<double>(), 1e-9);
  EXPECT_NEAR(ours.second[0][0].item<double>(), 1.0, 1e-12);
  EXPECT_NEAR(ours.second[1499][1299].item<double>(), 1.0, 1e-12);
  // Finite differences on an entry on the path (E ~ 1) and entries near 0.5 and 0.1.
  at::Tensor flat = ours.second.reshape(-1);
  const std::vector<int64_t> entries = {flat.argmax().item<int64_t>(), (flat - 0.5).abs().argmin().item<int64_t>(),
                                        (flat - 0.1).abs().argmin().item<int64_t>()};
  EXPECT_NEAR(flat[entries[1]].item<double>(), 0.5, 0.05);
  EXPECT_NEAR(flat[entries[2]].item<double>(), 0.1, 0.05);
  at::Tensor Dc = D.clone();
  for (int64_t k : entries) {
    const double fd = central_difference([&] { return soft_dtw(Dc, g).item<double>(); }, Dc, k, 1e-5);
    EXPECT_NEAR(flat[k].item<double>(), fd, 1e-6) << "entry " << k;
  }
  ThreadCount two(2);
  auto parallel = value_and_grad(D, g);
  EXPECT_EQ(parallel.first.item<double>(), v);
  EXPECT_TRUE(at::equal(parallel.second, ours.second));
}

TEST(SoftDtw, BadInputThrowsInputError) {
  at::Tensor D = at::rand({3, 4}, kF64);
  at::Tensor x = at::rand({2, 3, 2}, kF64), y = at::rand({2, 4, 2}, kF64);
  for (double g : {0.0, -1.0, std::nan(""), kInf}) {
    EXPECT_THROW(soft_dtw(D, g), InputError);
    EXPECT_THROW(soft_dtw_sequences(x, y, g), InputError);
    EXPECT_THROW(soft_dtw_divergence(x, y, g), InputError);
  }
  EXPECT_THROW(soft_dtw(at::Tensor(), 0.1), InputError);
  EXPECT_THROW(soft_dtw(at::rand({0, 4}, kF64), 0.1), InputError);
  EXPECT_THROW(soft_dtw(at::rand({2, 3, 0}, kF64), 0.1), InputError);
  EXPECT_THROW(soft_dtw(at::rand({4}, kF64), 0.1), InputError);
  EXPECT_THROW(soft_dtw(at::rand({1, 2, 3, 4}, kF64), 0.1), InputError);
  EXPECT_THROW(soft_dtw(at::ones({3, 4}, at::kInt), 0.1), InputError);
  at::Tensor bad = D.clone();
  bad[1][2] = std::nan("");
  EXPECT_THROW(soft_dtw(bad, 0.1), InputError);
  bad[1][2] = kInf;
  EXPECT_THROW(soft_dtw(bad, 0.1), InputError);
  EXPECT_THROW(soft_dtw_divergence(at::rand({2, 0, 2}, kF64), y, 0.1), InputError);  // empty sequence
  EXPECT_THROW(soft_dtw_divergence(x, at::rand({2, 4, 3}, kF64), 0.1), InputError);  // d differs
  EXPECT_THROW(soft_dtw_divergence(x, at::rand({3, 4, 2}, kF64), 0.1), InputError);  // batch differs
  EXPECT_THROW(soft_dtw_divergence(x[0], y[0], 0.1), InputError);                    // rank
  EXPECT_THROW(soft_dtw_divergence(x, y.to(at::kFloat), 0.1), InputError);           // dtype
  EXPECT_THROW(squared_euclidean_cost(x, at::Tensor()), InputError);
  at::Tensor xn = x.clone();
  xn[1][2][0] = -kInf;
  EXPECT_THROW(soft_dtw_divergence(xn, y, 0.1), InputError);
  EXPECT_THROW(soft_dtw_sequences(x, xn, 0.1), InputError);
  // An empty batch is not an error.
  EXPECT_EQ(soft_dtw(at::rand({0, 3, 4}, kF64), 0.1).numel(), 0);
  // Finite costs whose sum along every path overflows double.
  EXPECT_THROW(soft_dtw(at::full({2, 3, 4}, 1e308, kF64), 0.1), InputError);
  EXPECT_THROW(soft_dtw_sequences(at::full({1, 3, 2}, 1e154, kF64), at::full({1, 4, 2}, -1e154, kF64), 0.1),
               InputError);
}

// The torch-free kernel entry (the Eigen runtime's re-navigation energy) gives
// the torch function's value and gradient to the last bit, with sdtw(y, y)
// computed or given, and refuses what the torch function refuses.
TEST(SoftDtw, KernelDivergenceIsTheTorchDivergenceBitForBit) {
  at::manual_seed(11);
  const at::Tensor x = at::randn({1, 37, 6}, kF64), y = at::randn({1, 29, 6}, kF64);
  at::Tensor xg = x.clone().requires_grad_(true);
  const at::Tensor value = soft_dtw_divergence(xg, y, kNemfSoftDtwGamma);
  value.sum().backward();
  const at::Tensor grad = xg.grad().contiguous();

  const sdtw::RowMatrixXd xe = Eigen::Map<const sdtw::RowMatrixXd>(x.data_ptr<double>(), 37, 6);
  const sdtw::RowMatrixXd ye = Eigen::Map<const sdtw::RowMatrixXd>(y.data_ptr<double>(), 29, 6);
  sdtw::RowMatrixXd ge;
  EXPECT_EQ(sdtw::divergence(xe, ye, kNemfSoftDtwGamma, &ge), value.item<double>());
  ASSERT_EQ(ge.rows(), 37);
  ASSERT_EQ(ge.cols(), 6);
  const double* g = grad.data_ptr<double>();
  for (Eigen::Index k = 0; k < ge.size(); ++k) ASSERT_EQ(ge.data()[k], g[k]) << k;
  const double self_y = sdtw::self_value(ye, kNemfSoftDtwGamma);
  EXPECT_EQ(sdtw::divergence(xe, ye, kNemfSoftDtwGamma, nullptr, &self_y), value.item<double>());
  EXPECT_EQ(sdtw::divergence(xe, xe, kNemfSoftDtwGamma, nullptr), 0.0);

  EXPECT_THROW(sdtw::divergence(xe, ye.leftCols(5), 0.1, nullptr), InputError);
  EXPECT_THROW(sdtw::divergence(xe.topRows(0), ye, 0.1, nullptr), InputError);
  EXPECT_THROW(sdtw::divergence(xe, ye, 0.0, nullptr), InputError);
  sdtw::RowMatrixXd bad = xe;
  bad(3, 2) = std::nan("");
  EXPECT_THROW(sdtw::divergence(bad, ye, 0.1, &ge), InputError);
  // Finite values whose costs overflow double.
  EXPECT_THROW(sdtw::divergence(sdtw::RowMatrixXd::Constant(3, 2, 1e154), sdtw::RowMatrixXd::Constant(4, 2, -1e154),
                                0.1, nullptr),
               InputError);
}

}  // namespace
}  // namespace mf
