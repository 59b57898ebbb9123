// A finite-difference check of autograd gradients for the unit tests (GoogleTest
// assertions; linked into mf_tests only, unlike test_util.cc).
#pragma once

#include <ATen/ATen.h>

#include <cstdint>
#include <functional>
#include <string>

namespace mf::test {

/// Checks `param.grad()` (left by a backward of `loss(param)`) against central
/// differences of `loss` with every `stride`-th entry of `param` moved by +-h,
/// within tol * max(1, |difference quotient|). `loss` receives the moved copy
/// (no gradient) and returns a scalar; failures name `what` and the entry.
void expect_gradient_matches_finite_differences(const std::function<at::Tensor(const at::Tensor&)>& loss,
                                                const at::Tensor& param, const std::string& what, double h = 1e-6,
                                                double tol = 1e-6, int64_t stride = 1);

}  // namespace mf::test
