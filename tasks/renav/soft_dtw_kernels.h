// The soft-DTW kernels of tasks/reference/soft_dtw.h without libtorch: the
// recursion of one cost matrix, its backward, and the squared Euclidean cost
// of a sequence pair with its gradient, in double, on raw row-major buffers.
// soft_dtw.h wraps them in torch autograd functions (with their checks and
// threading); the Eigen runtime's re-navigation energy calls divergence()
// directly. Definitions, precision and memory: soft_dtw.h.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>

namespace mf {

/// The gamma NeMF uses for re-navigation.
inline constexpr double kNemfSoftDtwGamma = 0.1;

}  // namespace mf

namespace mf::sdtw {

/// Runs body(b, e) over sub-ranges [b, e) of [begin, end), possibly on several
/// threads (at::parallel_for in soft_dtw.cc); a null ParallelFor means the
/// calling thread alone.
using ParallelFor = void (*)(int64_t begin, int64_t end, int64_t grain,
                             const std::function<void(int64_t, int64_t)>& body);

/// A single matrix runs as a tiled wavefront (when a ParallelFor is given)
/// only when both its sides reach this.
inline constexpr int64_t kWavefrontMinSide = 512;

/// Sizes of one cost matrix and of its working memory. R is (m+1) x (n+1); P (the
/// soft-argmin probabilities of the diagonal, up and left predecessors) and G
/// (dValue/dR) are (m+2) x (n+2), so that the backward needs no bounds tests: the
/// padding row m+1 and column n+1 hold zeros, except the seed G[m+1][n+1] = 1
/// with P[m+1][n+1] = (1, 0, 0), which makes G[m][n] = 1.
struct Dims {
  int64_t m, n;
  int64_t rs() const { return n + 1; }
  int64_t ps() const { return n + 2; }
  int64_t p_size() const { return 3 * (m + 2) * (n + 2); }
  int64_t g_size() const { return (m + 2) * (n + 2); }
};

/// Soft-DTW of one cost matrix D [m, n] (row-major); fills P [dm.p_size()]
/// (when not null) with the soft-argmin probabilities for item_backward().
/// With `wavefront`, the 128 x 128 tiles of each anti-diagonal run in parallel.
template <typename T>
double item_forward(const T* D, Dims dm, double gamma, double* P, ParallelFor wavefront);

/// dValue/dR from the probabilities: G[i][j] for 1 <= i <= m, 1 <= j <= n is
/// dValue/dD[i-1][j-1] (stride dm.ps()).
std::unique_ptr<double[]> item_backward(const double* P, Dims dm, ParallelFor wavefront);

/// One cost matrix of a sequence pair: D[i][j] = |a_i - b_j|^2 = |a_i|^2 + |b_j|^2 -
/// 2 a_i.b_j (a [m, d], b [n, d]), through an Eigen matrix product (single-threaded):
/// 10x faster than the explicit differences, and in double the cancellation error
/// (~1e-16 (|a_i|^2 + |b_j|^2)) is far below any useful gamma. Clamped at 0. Equal
/// inputs give bitwise equal matrices, so the divergence stays exactly 0 at x = y.
void pair_cost(const double* a, int64_t m, const double* b, int64_t n, int64_t d, double* D);

/// Adds w dValue/da and w dValue/db for the pair's alignment E (G of
/// item_backward): with dD[i][j]/da_i = 2 (a_i - b_j) = -dD[i][j]/db_j,
///   ga_i += 2 w (sum_j E_ij a_i - sum_j E_ij b_j),  gb_j += 2 w (sum_i E_ij b_j - sum_i E_ij a_i).
/// Rows of a, then rows of b, each summed in a fixed order, so that the result
/// does not depend on how the rows are split over threads; ga and gb may alias (a = b).
void pair_grad(const double* G, Dims dm, const double* a, const double* b, int64_t d, double w, double* ga, double* gb,
               ParallelFor parallel);

using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// The soft-DTW divergence sdtw(x, y) - 1/2 sdtw(x, x) - 1/2 sdtw(y, y) of
/// x [m, d] and y [n, d] with the squared Euclidean cost, on the calling
/// thread; the same arithmetic as soft_dtw_divergence() (soft_dtw.h), so the
/// same value to the last bit. When `grad_x` is not null, dValue/dx [m, d]
/// is written to it. `self_y`, when given, is sdtw(y, y) (see self_value()),
/// saved when y is a constant reference. Throws InputError for empty or
/// mismatched sequences, non-finite values, a gamma that is not finite and
/// positive, or an overflowing cost.
double divergence(const RowMatrixXd& x, const RowMatrixXd& y, double gamma,
                  RowMatrixXd* grad_x, const double* self_y = nullptr);

/// sdtw(y, y) with the squared Euclidean cost (a term of divergence()).
double self_value(const RowMatrixXd& y, double gamma);

}  // namespace mf::sdtw
