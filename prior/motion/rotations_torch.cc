#include "prior/motion/rotations_torch.h"

#include <ATen/ATen.h>
#include <ATen/Dispatch.h>
#include <ATen/Parallel.h>
#include <torch/csrc/autograd/custom_function.h>

#include <cmath>
#include <string>
#include <vector>

#include "prior/motion/errors.h"
#include "prior/motion/rotation_kernels.h"

namespace mf::torch_rot {
namespace {

std::string shape_string(const at::Tensor& t) {
  std::string s = "[";
  for (int64_t i = 0; i < t.dim(); ++i) s += (i ? ", " : "") + std::to_string(t.size(i));
  return s + "]";
}

void require_last(const at::Tensor& t, int64_t size, const char* fn, const char* what) {
  if (!t.defined() || t.dim() < 1 || t.size(-1) != size)
    throw InputError(std::string(fn) + ": " + what + " must have shape [..., " + std::to_string(size) +
                     "], got " + (t.defined() ? shape_string(t) : std::string("an undefined tensor")));
}

void require_matrix(const at::Tensor& t, const char* fn, const char* what) {
  if (!t.defined() || t.dim() < 2 || t.size(-1) != 3 || t.size(-2) != 3)
    throw InputError(std::string(fn) + ": " + what + " must have shape [..., 3, 3], got " +
                     (t.defined() ? shape_string(t) : std::string("an undefined tensor")));
}

at::Tensor comp(const at::Tensor& t, int64_t i) { return t.select(-1, i); }
at::Tensor entry(const at::Tensor& m, int64_t r, int64_t c) { return m.select(-2, r).select(-1, c); }

// Stacks nine broadcast-compatible row-major entries into [..., 3, 3].
at::Tensor matrix_from_entries(std::vector<at::Tensor> e) {
  at::Tensor flat = at::stack(e, -1);
  std::vector<int64_t> shape(flat.sizes().begin(), flat.sizes().end() - 1);
  shape.push_back(3);
  shape.push_back(3);
  return flat.reshape(shape);
}

// Division by a clamped norm: the clamp keeps the gradient finite for zero vectors.
at::Tensor normalize_last(const at::Tensor& v) {
  return v * at::rsqrt((v * v).sum(-1, /*keepdim=*/true).clamp_min(1e-24));
}

at::Tensor cross3(const at::Tensor& a, const at::Tensor& b) {
  at::Tensor ax = comp(a, 0), ay = comp(a, 1), az = comp(a, 2);
  at::Tensor bx = comp(b, 0), by = comp(b, 1), bz = comp(b, 2);
  return at::stack({ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx}, -1);
}

// sqrt with a zero gradient (instead of infinity) for non-positive arguments.
at::Tensor sqrt_positive(const at::Tensor& x) {
  at::Tensor positive = x > 0;
  return at::where(positive, at::sqrt(at::where(positive, x, at::ones_like(x))), at::zeros_like(x));
}

// Gram-Schmidt of the 6D representation as one autograd node with a
// hand-written backward (kernels::sixd_to_matrix and its VJP, shared with the
// Eigen runtime): as tensor operations it was ~25 operators forward and as
// many backward nodes in every decode (per-operation overhead, not
// arithmetic, is what a latent solver's evaluation pays; see FK). Same clamp
// as normalize_last.
class SixdFunction : public torch::autograd::Function<SixdFunction> {
 public:
  // d6 [N, 6] contiguous float or double -> [N, 3, 3] (columns b1, b2, b3).
  static torch::autograd::variable_list forward(torch::autograd::AutogradContext* ctx, const at::Tensor& d6) {
    const int64_t N = d6.size(0);
    at::Tensor m = at::empty({N, 3, 3}, d6.options());
    AT_DISPATCH_FLOATING_TYPES(d6.scalar_type(), "sixd_to_matrix", [&] {
      const scalar_t* x = d6.data_ptr<scalar_t>();
      scalar_t* out = m.data_ptr<scalar_t>();
      at::parallel_for(0, N, 1024, [&](int64_t n0, int64_t n1) {
        for (int64_t n = n0; n < n1; ++n) kernels::sixd_to_matrix(x + n * 6, out + n * 9);
      });
    });
    ctx->save_for_backward({d6});
    return {m};
  }

  static torch::autograd::variable_list backward(torch::autograd::AutogradContext* ctx,
                                                 torch::autograd::variable_list grads) {
    const at::Tensor d6 = ctx->get_saved_variables()[0];
    const at::Tensor g = grads[0].contiguous();
    const int64_t N = d6.size(0);
    at::Tensor gd = at::empty_like(d6);
    AT_DISPATCH_FLOATING_TYPES(d6.scalar_type(), "sixd_to_matrix_backward", [&] {
      const scalar_t *x = d6.data_ptr<scalar_t>(), *gm = g.data_ptr<scalar_t>();
      scalar_t* out = gd.data_ptr<scalar_t>();
      at::parallel_for(0, N, 1024, [&](int64_t n0, int64_t n1) {
        for (int64_t n = n0; n < n1; ++n) kernels::sixd_to_matrix_vjp(x + n * 6, gm + n * 9, out + n * 6);
      });
    });
    return {gd};
  }
};

// The angle of the relative rotation m0^T m1 as one autograd node
// (kernels::geodesic_angle and its VJP; it was ~60 operators forward and as
// many backward through matrix_to_quat, in every evaluation of the key
// terms). atan2(|skew part|, (trace - 1) / 2) is the same value as
// 2 atan2(|xyz|, |w|) of the quaternion; the gradients agree along
// rotations, which is all a 6D decode can move.
class GeodesicFunction : public torch::autograd::Function<GeodesicFunction> {
 public:
  // m0, m1 [N, 3, 3] contiguous, same floating type -> [N].
  static torch::autograd::variable_list forward(torch::autograd::AutogradContext* ctx, const at::Tensor& m0,
                                                const at::Tensor& m1) {
    const int64_t N = m0.size(0);
    at::Tensor angle = at::empty({N}, m0.options());
    AT_DISPATCH_FLOATING_TYPES(m0.scalar_type(), "geodesic_angle", [&] {
      const scalar_t *A = m0.data_ptr<scalar_t>(), *B = m1.data_ptr<scalar_t>();
      scalar_t* out = angle.data_ptr<scalar_t>();
      at::parallel_for(0, N, 2048, [&](int64_t n0, int64_t n1) {
        for (int64_t n = n0; n < n1; ++n) out[n] = kernels::geodesic_angle(A + n * 9, B + n * 9);
      });
    });
    ctx->save_for_backward({m0, m1});
    return {angle};
  }

  static torch::autograd::variable_list backward(torch::autograd::AutogradContext* ctx,
                                                 torch::autograd::variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const at::Tensor &m0 = saved[0], &m1 = saved[1];
    const at::Tensor g = grads[0].contiguous();
    const bool want0 = ctx->needs_input_grad(0), want1 = ctx->needs_input_grad(1);
    const int64_t N = m0.size(0);
    at::Tensor g0 = want0 ? at::empty_like(m0) : at::Tensor();
    at::Tensor g1 = want1 ? at::empty_like(m1) : at::Tensor();
    AT_DISPATCH_FLOATING_TYPES(m0.scalar_type(), "geodesic_angle_backward", [&] {
      const scalar_t *A = m0.data_ptr<scalar_t>(), *B = m1.data_ptr<scalar_t>(), *gn = g.data_ptr<scalar_t>();
      scalar_t* out0 = want0 ? g0.data_ptr<scalar_t>() : nullptr;
      scalar_t* out1 = want1 ? g1.data_ptr<scalar_t>() : nullptr;
      at::parallel_for(0, N, 2048, [&](int64_t n0, int64_t n1) {
        for (int64_t n = n0; n < n1; ++n) {
          kernels::geodesic_angle_vjp(A + n * 9, B + n * 9, gn[n], out0 ? out0 + n * 9 : nullptr,
                                      out1 ? out1 + n * 9 : nullptr);
        }
      });
    });
    return {g0, g1};
  }
};

}  // namespace

at::Tensor quat_normalize(const at::Tensor& q) {
  require_last(q, 4, "quat_normalize", "q");
  return normalize_last(q);
}

at::Tensor quat_multiply(const at::Tensor& a, const at::Tensor& b) {
  require_last(a, 4, "quat_multiply", "a");
  require_last(b, 4, "quat_multiply", "b");
  at::Tensor aw = comp(a, 0), ax = comp(a, 1), ay = comp(a, 2), az = comp(a, 3);
  at::Tensor bw = comp(b, 0), bx = comp(b, 1), by = comp(b, 2), bz = comp(b, 3);
  return at::stack({aw * bw - ax * bx - ay * by - az * bz,
                    aw * bx + ax * bw + ay * bz - az * by,
                    aw * by - ax * bz + ay * bw + az * bx,
                    aw * bz + ax * by - ay * bx + az * bw},
                   -1);
}

at::Tensor quat_conjugate(const at::Tensor& q) {
  require_last(q, 4, "quat_conjugate", "q");
  return at::cat({q.narrow(-1, 0, 1), -q.narrow(-1, 1, 3)}, -1);
}

at::Tensor quat_rotate(const at::Tensor& q, const at::Tensor& v) {
  require_last(q, 4, "quat_rotate", "q");
  require_last(v, 3, "quat_rotate", "v");
  // v' = v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z), for unit q.
  at::Tensor w = q.narrow(-1, 0, 1);
  at::Tensor u = q.narrow(-1, 1, 3);
  at::Tensor uv = cross3(u, v);
  return v + 2 * (w * uv + cross3(u, uv));
}

at::Tensor quat_to_matrix(const at::Tensor& q) {
  require_last(q, 4, "quat_to_matrix", "q");
  at::Tensor w = comp(q, 0), x = comp(q, 1), y = comp(q, 2), z = comp(q, 3);
  // s = 2 / |q|^2 makes the result a rotation for non-unit q as well.
  at::Tensor s = 2.0 / (q * q).sum(-1).clamp_min(1e-24);
  at::Tensor xx = x * x * s, yy = y * y * s, zz = z * z * s;
  at::Tensor xy = x * y * s, xz = x * z * s, yz = y * z * s;
  at::Tensor wx = w * x * s, wy = w * y * s, wz = w * z * s;
  return matrix_from_entries({1 - yy - zz, xy - wz, xz + wy,
                              xy + wz, 1 - xx - zz, yz - wx,
                              xz - wy, yz + wx, 1 - xx - yy});
}

at::Tensor matrix_to_quat(const at::Tensor& m) {
  require_matrix(m, "matrix_to_quat", "m");
  at::Tensor m00 = entry(m, 0, 0), m01 = entry(m, 0, 1), m02 = entry(m, 0, 2);
  at::Tensor m10 = entry(m, 1, 0), m11 = entry(m, 1, 1), m12 = entry(m, 1, 2);
  at::Tensor m20 = entry(m, 2, 0), m21 = entry(m, 2, 1), m22 = entry(m, 2, 2);
  // 4w^2, 4x^2, 4y^2, 4z^2 from the diagonal; they sum to 4, so the largest is >= 1
  // and the candidate built from it divides by at least 2.
  at::Tensor four_sq = at::stack({1 + m00 + m11 + m22, 1 + m00 - m11 - m22,
                                  1 - m00 + m11 - m22, 1 - m00 - m11 + m22}, -1);
  at::Tensor two_abs = sqrt_positive(four_sq);  // 2|w|, 2|x|, 2|y|, 2|z|
  at::Tensor a0 = comp(two_abs, 0), a1 = comp(two_abs, 1), a2 = comp(two_abs, 2), a3 = comp(two_abs, 3);
  // Row k: 4 * q_k * q, a valid quaternion (up to scale) whenever q_k != 0.
  at::Tensor cand = at::stack(
      {at::stack({a0 * a0, m21 - m12, m02 - m20, m10 - m01}, -1),
       at::stack({m21 - m12, a1 * a1, m10 + m01, m02 + m20}, -1),
       at::stack({m02 - m20, m10 + m01, a2 * a2, m12 + m21}, -1),
       at::stack({m10 - m01, m20 + m02, m21 + m12, a3 * a3}, -1)},
      -2);
  // Unselected rows may divide by ~0; the floor keeps their (discarded) values
  // and gradients finite.
  cand = cand / (2 * two_abs.unsqueeze(-1)).clamp_min(0.1);
  at::Tensor best = four_sq.detach().argmax(-1, /*keepdim=*/true);  // [..., 1]
  std::vector<int64_t> index_shape(cand.sizes().begin(), cand.sizes().end());
  index_shape[index_shape.size() - 2] = 1;
  at::Tensor q = cand.gather(-2, best.unsqueeze(-1).expand(index_shape)).squeeze(-2);
  q = normalize_last(q);
  at::Tensor sign = at::where(q.narrow(-1, 0, 1).detach() < 0, -at::ones_like(q.narrow(-1, 0, 1)),
                              at::ones_like(q.narrow(-1, 0, 1)));
  return q * sign;
}

at::Tensor matrix_to_sixd(const at::Tensor& m) {
  require_matrix(m, "matrix_to_sixd", "m");
  return at::cat({m.select(-1, 0), m.select(-1, 1)}, -1);
}

at::Tensor sixd_to_matrix(const at::Tensor& d6) {
  require_last(d6, 6, "sixd_to_matrix", "d6");
  if (!at::isFloatingType(d6.scalar_type()))
    throw InputError("sixd_to_matrix: d6 must be a floating-point tensor, got " + std::string(c10::toString(d6.scalar_type())));
  const at::ScalarType work = d6.scalar_type() == at::kDouble ? at::kDouble : at::kFloat;
  std::vector<int64_t> shape(d6.sizes().begin(), d6.sizes().end() - 1);
  shape.insert(shape.end(), {3, 3});
  return SixdFunction::apply(d6.to(work).reshape({-1, 6}).contiguous())[0].view(shape).to(d6.scalar_type());
}

at::Tensor quat_slerp(const at::Tensor& q0, const at::Tensor& q1, const at::Tensor& t) {
  require_last(q0, 4, "quat_slerp", "q0");
  require_last(q1, 4, "quat_slerp", "q1");
  if (!t.defined()) throw InputError("quat_slerp: t is an undefined tensor");
  const at::Tensor a = normalize_last(q0), b = normalize_last(q1);
  at::Tensor dot = (a * b).sum(-1, /*keepdim=*/true);
  at::Tensor flip = at::where(dot.detach() < 0, -at::ones_like(dot), at::ones_like(dot));
  const at::Tensor bs = b * flip;
  dot = dot * flip;
  // Same threshold as the Eigen slerp in rotations.cc.
  at::Tensor near = dot.detach() > 0.9995;
  at::Tensor nlerp = a * (1 - t) + bs * t;
  // The slerp branch is evaluated on a safe dot where nlerp is used, so that
  // acos and 1/sin never see 1 and the discarded gradients stay finite.
  at::Tensor dot_safe = at::where(near, at::zeros_like(dot), dot.clamp(-1.0, 1.0));
  at::Tensor theta = at::acos(dot_safe);
  at::Tensor inv_sin = 1.0 / at::sin(theta);
  at::Tensor slerp = a * (at::sin((1 - t) * theta) * inv_sin) + bs * (at::sin(t * theta) * inv_sin);
  return normalize_last(at::where(near, nlerp, slerp));
}

at::Tensor geodesic_angle(const at::Tensor& m0, const at::Tensor& m1) {
  require_matrix(m0, "geodesic_angle", "m0");
  require_matrix(m1, "geodesic_angle", "m1");
  for (const at::Tensor* m : {&m0, &m1}) {
    if (!at::isFloatingType(m->scalar_type()))
      throw InputError("geodesic_angle: the matrices must be floating-point tensors, got " +
                       std::string(c10::toString(m->scalar_type())));
  }
  const at::ScalarType out_type = at::promote_types(m0.scalar_type(), m1.scalar_type());
  const at::ScalarType work = out_type == at::kDouble ? at::kDouble : at::kFloat;
  at::Tensor a = m0.to(work), b = m1.to(work);
  if (a.sizes() != b.sizes()) {
    std::vector<at::Tensor> both = at::broadcast_tensors({a, b});
    a = both[0];
    b = both[1];
  }
  std::vector<int64_t> shape(a.sizes().begin(), a.sizes().end() - 2);
  return GeodesicFunction::apply(a.reshape({-1, 3, 3}).contiguous(), b.reshape({-1, 3, 3}).contiguous())[0]
      .view(shape)
      .to(out_type);
}

at::Tensor quat_make_continuous(const at::Tensor& q, int64_t dim) {
  require_last(q, 4, "quat_make_continuous", "q");
  const int64_t nd = q.dim();
  const int64_t d = dim < 0 ? dim + nd : dim;
  if (d < 0 || d >= nd - 1)
    throw InputError("quat_make_continuous: dim " + std::to_string(dim) + " is out of range for a tensor of shape " +
                     shape_string(q) + " (the last dimension holds the quaternion)");
  dim = d;
  const int64_t n = q.size(dim);
  if (n < 2) return q;
  at::Tensor qd = q.detach();
  at::Tensor dots = (qd.narrow(dim, 1, n - 1) * qd.narrow(dim, 0, n - 1)).sum(-1, /*keepdim=*/true);
  at::Tensor step = at::where(dots < 0, -at::ones_like(dots), at::ones_like(dots));
  std::vector<int64_t> first_shape(step.sizes().begin(), step.sizes().end());
  first_shape[dim] = 1;
  at::Tensor signs = at::cat({at::ones(first_shape, step.options()), step}, dim).cumprod(dim);
  return q * signs;
}

at::Tensor matmul3(const at::Tensor& a, const at::Tensor& b) { return (a.unsqueeze(-1) * b.unsqueeze(-3)).sum(-2); }

at::Tensor matvec3(const at::Tensor& m, const at::Tensor& v) { return (m * v.unsqueeze(-2)).sum(-1); }

}  // namespace mf::torch_rot
