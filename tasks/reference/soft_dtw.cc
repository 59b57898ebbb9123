#include "tasks/reference/soft_dtw.h"

#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <torch/csrc/autograd/custom_function.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "prior/motion/errors.h"
#include "tasks/renav/soft_dtw_kernels.h"

namespace mf {
namespace {

using sdtw::Dims;
using sdtw::item_backward;
using sdtw::item_forward;
using sdtw::kWavefrontMinSide;
using sdtw::pair_cost;
using sdtw::pair_grad;

// at::parallel_for as the kernels' ParallelFor (an OpenMP loop in GCC builds).
void torch_parallel_for(int64_t begin, int64_t end, int64_t grain, const std::function<void(int64_t, int64_t)>& body) {
  at::parallel_for(begin, end, grain, body);
}

// Below this many cells in a call, everything stays on the calling thread: waking
// a second OpenMP thread costs milliseconds when the other core is busy.
constexpr int64_t kMinParallelCells = int64_t{1} << 16;

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

// How B items of `cells` cells each are spread over threads.
struct Plan {
  bool batch_parallel = false;
  int64_t grain = 1;
  bool wavefront = false;  // inside each item, for matrices with both sides >= kWavefrontMinSide
  sdtw::ParallelFor wavefront_for(Dims dm) const {
    return wavefront && std::min(dm.m, dm.n) >= kWavefrontMinSide ? torch_parallel_for : nullptr;
  }
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
          const sdtw::ParallelFor wavefront = plan.wavefront_for(p.dm);
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
          const sdtw::ParallelFor wavefront = plan.wavefront_for(p.dm);
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
