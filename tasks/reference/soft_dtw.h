// Soft-DTW (Cuturi and Blondel 2017) and the soft-DTW divergence (Blondel, Mensch
// and Vert 2021), exact O(m n) forward and backward on the CPU, differentiable
// through torch autograd. Used by the re-navigation energy (REFERENCE.md section 5,
// NeMF: gamma 0.1 on joint positions in the heading frame and on the
// heading-vs-tangent angle).
//
// Definition. For a cost matrix D [m, n] the recursion runs over R of size
// (m+1) x (n+1) with R[0,0] = 0 and the other borders +inf:
//   R[i,j] = D[i-1,j-1] + softmin_gamma(R[i-1,j-1], R[i-1,j], R[i,j-1]),
//   softmin_gamma(a, b, c) = -gamma log(exp(-a/gamma) + exp(-b/gamma) + exp(-c/gamma)),
// evaluated with the log-sum-exp shift by the smallest argument; the value is R[m,n].
// As gamma -> 0 the value tends to the hard DTW cost (min over monotone
// alignments of the summed costs) from below: hard - gamma log(3) (m+n-1) <= value <= hard.
//
// Gradient. dValue/dD is the expected alignment matrix E (entries in [0, 1], the
// soft-argmin-weighted probability that cell (i, j) lies on the alignment path).
// The forward stores the three soft-argmin probabilities of every cell, so the
// backward is a linear recursion without exponentials (no overflow, no loss of
// precision at any length). First-order only: the backward itself is not
// differentiated again (no double backward).
//
// Precision and memory. Whatever the input dtype (float32 or float64), the
// recursion runs in double; results are returned in the input's dtype. Soft-argmin
// weights below ~1e-150 and entries of E below 1e-150 are set to 0 (this keeps the
// arithmetic out of the slow denormal range; far below double rounding of E).
// Memory per cost matrix while a graph holds the result: 3 (m+2)(n+2) doubles
// for the probabilities (m = n = 128: 0.4 MB; 1024: 25 MB; 4096: 403 MB); the
// forward needs another (m+1)(n+1) doubles for R and the backward (m+2)(n+2)
// doubles, both freed on return. Without grad (no input requiring grad, or grad
// mode off) the probabilities are not stored. No length limit other than memory.
//
// Threads. Batch items run in parallel with at::parallel_for when the batch is
// large enough, and a single large matrix (both sides >= 512) runs as a
// wavefront of 128 x 128 tiles; calls with fewer than 64K cells in total stay on
// the calling thread (waking a second thread costs more than it saves, and
// milliseconds when the other core is busy). No torch op with internal
// threading runs on the hot path. Results are bitwise identical for every
// thread count. at::parallel_for is an inline OpenMP loop: GCC builds compile
// with -fopenmp (CMakeLists.txt) and run these loops in parallel; clang builds
// (sanitizers, fuzzing) run them on the calling thread.
//
// Cost of the sequence functions: the squared Euclidean cost matrices and their
// gradients are computed inside the C++ kernel in double (an Eigen product
// |a|^2 + |b|^2 - 2 a.b, clamped at 0), not through torch ops; the divergence
// of [1, 128, 66] against a constant reference costs a few ms forward+backward
// on one thread (bench/soft_dtw_bench.cc).
//
// Errors. Every function throws mf::InputError for: undefined or non-CPU
// tensors, dtypes other than float32/float64, wrong ranks or mismatched sizes,
// empty sequences (a length of 0), non-finite values, gamma not finite or <= 0,
// and for costs so large that the accumulated value overflows double.
#pragma once

#include <ATen/core/Tensor.h>

#include "tasks/renav/soft_dtw_kernels.h"  // kNemfSoftDtwGamma

namespace mf {

/// Soft-DTW value of cost matrices: `cost` [m, n] -> scalar [], or [B, m, n] -> [B],
/// in cost's dtype. Any real costs (negative ones too). Differentiable with respect
/// to `cost` (the gradient is the expected alignment times the incoming gradient).
/// m, n >= 1; B may be 0 (empty result).
at::Tensor soft_dtw(const at::Tensor& cost, double gamma);

/// Squared Euclidean cost between the frames of two batched sequences:
/// x [Bx, m, d], y [By, n, d] -> C [B, m, n] with C[b,i,j] = sum_k (x[b,i,k] - y[b,j,k])^2
/// (the full squared distance, not half of it, as in NeMF's soft-DTW; gamma is
/// relative to this scale). Bx and By are equal, or one of them is 1 and
/// broadcasts (B is the other). x and y share the dtype (float32 or float64); a
/// per-frame scalar is d = 1. Built from torch ops as explicit differences
/// (differentiable in x and y; memory B m n d), for composing other losses with
/// soft_dtw(); the two functions below do not use it (they compute the same
/// matrix faster inside their kernel).
at::Tensor squared_euclidean_cost(const at::Tensor& x, const at::Tensor& y);

/// soft_dtw(squared_euclidean_cost(x, y), gamma) in one kernel:
/// x [Bx, m, d], y [By, n, d] (batch 1 broadcasts as above) -> [B], in x's dtype.
/// Differentiable in x and y (a gradient is computed only for inputs that require
/// one). Can be negative and sdtw(x, x) != 0; use the divergence as a loss.
at::Tensor soft_dtw_sequences(const at::Tensor& x, const at::Tensor& y, double gamma);

/// Soft-DTW divergence  sdtw(x, y) - 1/2 sdtw(x, x) - 1/2 sdtw(y, y)  with the
/// squared Euclidean cost, in one kernel: x [Bx, m, d], y [By, n, d] (batch 1
/// broadcasts) -> [B], in x's dtype. m and n may differ. Non-negative (the
/// Gaussian kernel is positive definite; Blondel et al. 2021), exactly 0 where
/// x[b] = y[b] (with a zero gradient there), symmetric, differentiable in x and y.
/// The three terms cost 3 soft-DTW passes; the term of an input that does not
/// require grad stores no probabilities. For re-navigation:
///   soft_dtw_divergence(joints_in_heading_frame  /* [B, T, J*3], requires grad */,
///                       reference_joints         /* [1, T, J*3], constant */, kNemfSoftDtwGamma)
at::Tensor soft_dtw_divergence(const at::Tensor& x, const at::Tensor& y, double gamma);

}  // namespace mf
