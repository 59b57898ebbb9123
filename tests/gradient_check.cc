#include "tests/gradient_check.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace mf::test {

void expect_gradient_matches_finite_differences(const std::function<at::Tensor(const at::Tensor&)>& loss,
                                                const at::Tensor& param, const std::string& what, double h, double tol,
                                                int64_t stride) {
  ASSERT_TRUE(param.grad().defined()) << what << ": no gradient";
  const at::Tensor grad = param.grad().reshape({-1});
  ASSERT_TRUE(at::isfinite(grad).all().item<bool>()) << what;
  for (int64_t i = 0; i < param.numel(); i += stride) {
    at::Tensor plus = param.detach().clone(), minus = param.detach().clone();
    plus.view({-1})[i] += h;
    minus.view({-1})[i] -= h;
    const double fd = (loss(plus).item<double>() - loss(minus).item<double>()) / (2 * h);
    EXPECT_NEAR(grad[i].item<double>(), fd, tol * std::max(1.0, std::abs(fd))) << what << " entry " << i;
  }
}

}  // namespace mf::test
