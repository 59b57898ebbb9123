// Ground-truth keyframe scores for KeyframeNet (prior/inbetween/keyframe_net.h)
// by the Salient Poses dynamic programme (Roberts, Hoff, Duh, Anderson 2018 as
// summarised in REFERENCE.md section 4).
//
// Of a stretch of n frames with joint positions p_t (any fixed frame, metres):
//   - the cost of a span i < j is the error of approximating the frames between
//     i and j by interpolating between i and j: the maximum over i < t < j of
//     the summed joint position errors sum_k |p_t,k - lerp(p_i,k, p_j,k, w)|,
//     w = (t - i) / (j - i) (0 for j = i + 1);
//   - a keyframe set always holds the first and the last frame; its cost is the
//     sum of its spans' costs; salient_keyframe_sets() finds the optimal set of
//     every count 2..max_count (dynamic programme over (count, last frame),
//     O(max_count * n^2) after the O(n^3 J) span costs; ties keep the earlier
//     frame).
//   - salient_scores(): a frame's score is the fraction of the counts 2..K whose
//     optimal set holds it, K = min(n, ceil((n - 1) / min_spacing) + 1) (the
//     sets whose mean spacing is at least min_spacing). The first and the last
//     frame score 1; a frame that only the densest sets use scores near 0.
#pragma once

#include <ATen/core/Tensor.h>

#include <vector>

namespace mf::training {

/// Span costs [n, n] (entry (i, j) for i < j; 0 elsewhere) of joint positions [n, J, 3].
std::vector<std::vector<double>> salient_span_costs(const at::Tensor& positions);

/// The optimal keyframe sets (increasing frame indices) for the counts
/// 2..max_count (element k - 2 holds count k) of joint positions [n, J, 3], n >= 2;
/// max_count is clamped to [2, n].
std::vector<std::vector<int>> salient_keyframe_sets(const at::Tensor& positions, int max_count);

/// Per-frame scores [n] in [0, 1] (float), as described above; min_spacing >= 1.
at::Tensor salient_scores(const at::Tensor& positions, int min_spacing);

}  // namespace mf::training
