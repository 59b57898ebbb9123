#include "training/salient_poses.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "prior/motion/errors.h"

namespace mf::training {

std::vector<std::vector<double>> salient_span_costs(const at::Tensor& positions) {
  if (positions.dim() != 3 || positions.size(2) != 3) throw InputError("salient poses: positions must be [n, J, 3]");
  at::Tensor p = positions.detach().to(at::kDouble).contiguous().cpu();
  const int n = static_cast<int>(p.size(0)), J = static_cast<int>(p.size(1));
  const double* x = p.data_ptr<double>();
  const int stride = 3 * J;
  std::vector<std::vector<double>> cost(n, std::vector<double>(n, 0.0));
  for (int i = 0; i < n; ++i) {
    for (int j = i + 2; j < n; ++j) {
      double worst = 0.0;
      for (int t = i + 1; t < j; ++t) {
        const double w = static_cast<double>(t - i) / (j - i);
        double sum = 0.0;
        for (int k = 0; k < J; ++k) {
          double d2 = 0.0;
          for (int a = 0; a < 3; ++a) {
            const int o = 3 * k + a;
            const double e = x[t * stride + o] - ((1.0 - w) * x[i * stride + o] + w * x[j * stride + o]);
            d2 += e * e;
          }
          sum += std::sqrt(d2);
        }
        worst = std::max(worst, sum);
      }
      cost[i][j] = worst;
    }
  }
  return cost;
}

std::vector<std::vector<int>> salient_keyframe_sets(const at::Tensor& positions, int max_count) {
  const auto cost = salient_span_costs(positions);
  const int n = static_cast<int>(cost.size());
  if (n < 2) throw InputError("salient poses: need at least 2 frames");
  const int K = std::clamp(max_count, 2, n);
  const double inf = std::numeric_limits<double>::infinity();
  // best[k][j]: least cost of k keyframes from frame 0 ending at frame j; from[k][j] the previous one.
  std::vector<std::vector<double>> best(K + 1, std::vector<double>(n, inf));
  std::vector<std::vector<int>> from(K + 1, std::vector<int>(n, -1));
  best[1][0] = 0.0;
  for (int k = 2; k <= K; ++k) {
    for (int j = k - 1; j < n; ++j) {
      for (int i = k - 2; i < j; ++i) {
        const double c = best[k - 1][i] + cost[i][j];
        if (c < best[k][j]) {
          best[k][j] = c;
          from[k][j] = i;
        }
      }
    }
  }
  std::vector<std::vector<int>> sets;
  for (int k = 2; k <= K; ++k) {
    std::vector<int> set;
    for (int j = n - 1, c = k; j >= 0 && c >= 1; j = from[c][j], --c) set.push_back(j);
    std::reverse(set.begin(), set.end());
    sets.push_back(set);
  }
  return sets;
}

at::Tensor salient_scores(const at::Tensor& positions, int min_spacing) {
  if (min_spacing < 1) throw InputError("salient poses: min_spacing must be at least 1");
  const int n = static_cast<int>(positions.size(0));
  at::Tensor scores = at::zeros({n}, at::kFloat);
  if (n < 2) return scores.fill_(1.0f);
  const int K = std::min(n, (n - 1 + min_spacing - 1) / min_spacing + 1);
  const auto sets = salient_keyframe_sets(positions, K);
  float* s = scores.data_ptr<float>();
  for (const auto& set : sets) {
    for (int t : set) s[t] += 1.0f;
  }
  return scores / static_cast<float>(sets.size());
}

}  // namespace mf::training
