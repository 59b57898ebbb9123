// Per-element kernels of the quaternion steps the residual blend
// differentiates (rotations_torch.h: matrix_to_quat, quat_slerp,
// quat_to_matrix), with their hand-written gradients, on plain arrays (float
// or double), formula by formula as the libtorch functions. Torch-free: the
// Eigen runtime's blend (tasks/latent/runtime_blend.h, in double) and its float
// conversions (prior/runtime/rotations.h) run these same functions.
// Quaternions are (w, x, y, z); matrices row-major 3x3 (9 values).
#pragma once

#include <algorithm>
#include <cmath>

namespace mf::kernels {

/// The squared-norm floor of rotations_torch.h's normalize_last and quat_to_matrix.
constexpr double kQuatNormFloor = 1e-24;

template <typename T>
T dot4(const T* a, const T* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]; }

/// out += s * (g - (g.n) n): the gradient through a normalisation n = v s, s = 1/|v|.
template <typename T>
void add_through_normalisation(const T* g, const T* n, T s, T* out) {
  const T p = dot4(g, n);
  for (int i = 0; i < 4; ++i) out[i] += s * (g[i] - p * n[i]);
}

/// matrix_to_quat: 4 q_k q, the row of the candidate matrix built from the
/// largest of 4w^2, 4x^2, 4y^2, 4z^2 (fs = 1 +- m00 +- m11 +- m22), over
/// 2 sqrt(fs) (>= 2: no clamp), normalised, w made >= 0. The candidate matrix
/// is symmetric; its off-diagonal entries are m[p] + sign m[q].
constexpr int kDiagonalSigns[4][3] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
struct OffDiagonal {
  int p, q;
  int sign;
};
constexpr OffDiagonal kOffDiagonal[4][4] = {{{0, 0, 0}, {7, 5, -1}, {2, 6, -1}, {3, 1, -1}},
                                            {{7, 5, -1}, {0, 0, 0}, {3, 1, 1}, {2, 6, 1}},
                                            {{2, 6, -1}, {3, 1, 1}, {0, 0, 0}, {5, 7, 1}},
                                            {{3, 1, -1}, {2, 6, 1}, {5, 7, 1}, {0, 0, 0}}};

template <typename T>
struct MatrixQuat {
  int best = 0;
  T a, den, c[4], r[4], inv, sign, q[4];
  explicit MatrixQuat(const T* m) {
    T fs[4];
    for (int k = 0; k < 4; ++k)
      fs[k] = 1 + kDiagonalSigns[k][0] * m[0] + kDiagonalSigns[k][1] * m[4] + kDiagonalSigns[k][2] * m[8];
    for (int k = 1; k < 4; ++k) best = fs[k] > fs[best] ? k : best;
    a = std::sqrt(fs[best]);
    den = std::max(2 * a, T(0.1));
    for (int i = 0; i < 4; ++i) {
      const OffDiagonal& o = kOffDiagonal[best][i];
      c[i] = i == best ? a * a : m[o.p] + o.sign * m[o.q];
      r[i] = c[i] / den;
    }
    inv = 1 / std::sqrt(std::max(dot4(r, r), T(kQuatNormFloor)));
    sign = r[0] * inv < 0 ? T(-1) : T(1);
    for (int i = 0; i < 4; ++i) q[i] = sign * r[i] * inv;
  }
};

/// gm [9] += the gradient with respect to m of <gq, matrix_to_quat(m)>.
template <typename T>
void matrix_to_quat_vjp(const T* m, const T* gq, T* gm) {
  const MatrixQuat<T> f(m);
  T g_signed[4], n[4], g_r[4] = {0, 0, 0, 0};
  for (int i = 0; i < 4; ++i) g_signed[i] = f.sign * gq[i], n[i] = f.r[i] * f.inv;
  add_through_normalisation(g_signed, n, f.inv, g_r);
  T g_den = 0;
  for (int i = 0; i < 4; ++i) g_den -= g_r[i] * f.c[i] / (f.den * f.den);
  const T g_a = (2 * f.a >= T(0.1) ? 2 * g_den : T(0)) + 2 * f.a * g_r[f.best] / f.den;
  const T g_fs = g_a / (2 * f.a);
  for (int d = 0; d < 3; ++d) gm[d * 4] += kDiagonalSigns[f.best][d] * g_fs;
  for (int i = 0; i < 4; ++i) {
    if (i == f.best) continue;
    const OffDiagonal& o = kOffDiagonal[f.best][i];
    gm[o.p] += g_r[i] / f.den;
    gm[o.q] += o.sign * g_r[i] / f.den;
  }
}

/// quat_slerp: both ends normalised, b flipped into a's hemisphere, NLERP
/// above a cosine of 0.9995, the result normalised.
template <typename T>
struct Slerp {
  T na, nb, a[4], b[4], bs[4], flip, dot, t, u, v, theta = 0, r[4], inv, q[4];
  bool near;
  Slerp(const T* qa, const T* qb, T t_) : t(t_) {
    na = 1 / std::sqrt(std::max(dot4(qa, qa), T(kQuatNormFloor)));
    nb = 1 / std::sqrt(std::max(dot4(qb, qb), T(kQuatNormFloor)));
    for (int i = 0; i < 4; ++i) a[i] = qa[i] * na, b[i] = qb[i] * nb;
    dot = dot4(a, b);
    flip = dot < 0 ? T(-1) : T(1);
    for (int i = 0; i < 4; ++i) bs[i] = b[i] * flip;
    dot *= flip;
    near = dot > T(0.9995);
    if (near) {
      u = 1 - t, v = t;
    } else {
      theta = std::acos(std::clamp(dot, T(-1), T(1)));
      const T inv_sin = 1 / std::sin(theta);
      u = std::sin((1 - t) * theta) * inv_sin;
      v = std::sin(t * theta) * inv_sin;
    }
    for (int i = 0; i < 4; ++i) r[i] = a[i] * u + bs[i] * v;
    inv = 1 / std::sqrt(std::max(dot4(r, r), T(kQuatNormFloor)));
    for (int i = 0; i < 4; ++i) q[i] = r[i] * inv;
  }
};

/// g_qa, g_qb [4] += the gradients of <gq, slerp(qa, qb, t)>.
template <typename T>
void slerp_vjp(const T* qa, const T* qb, T t, const T* gq, T* g_qa, T* g_qb) {
  const Slerp<T> f(qa, qb, t);
  T g_r[4] = {0, 0, 0, 0}, g_a[4], g_bs[4], g_b[4];
  add_through_normalisation(gq, f.q, f.inv, g_r);
  for (int i = 0; i < 4; ++i) g_a[i] = g_r[i] * f.u, g_bs[i] = g_r[i] * f.v;
  if (!f.near) {
    const T sin_t = std::sin(f.theta), cos_t = std::cos(f.theta);
    const T du = ((1 - t) * std::cos((1 - t) * f.theta) * sin_t - std::sin((1 - t) * f.theta) * cos_t) /
                      (sin_t * sin_t);
    const T dv = (t * std::cos(t * f.theta) * sin_t - std::sin(t * f.theta) * cos_t) / (sin_t * sin_t);
    const T g_dot = (dot4(g_r, f.a) * du + dot4(g_r, f.bs) * dv) * (-1 / std::sqrt(1 - f.dot * f.dot));
    for (int i = 0; i < 4; ++i) g_a[i] += g_dot * f.bs[i], g_bs[i] += g_dot * f.a[i];
  }
  for (int i = 0; i < 4; ++i) g_b[i] = g_bs[i] * f.flip;
  add_through_normalisation(g_a, f.a, f.na, g_qa);
  add_through_normalisation(g_b, f.b, f.nb, g_qb);
}

/// quat_to_matrix: I + s P(q), s = 2 / |q|^2 (row-major m [9]).
template <typename T>
void quat_to_matrix(const T* q, T* m) {
  const T s = 2 / std::max(dot4(q, q), T(kQuatNormFloor));
  const T w = q[0], x = q[1], y = q[2], z = q[3];
  const T xx = x * x * s, yy = y * y * s, zz = z * z * s, xy = x * y * s, xz = x * z * s, yz = y * z * s;
  const T wx = w * x * s, wy = w * y * s, wz = w * z * s;
  const T r[9] = {1 - yy - zz, xy - wz, xz + wy, xy + wz, 1 - xx - zz, yz - wx, xz - wy, yz + wx, 1 - xx - yy};
  std::copy(r, r + 9, m);
}

/// gq [4] = the gradient with respect to q of <gm, quat_to_matrix(q)>.
template <typename T>
void quat_to_matrix_vjp(const T* q, const T* gm, T* gq) {
  const T n2 = dot4(q, q), s = 2 / std::max(n2, T(kQuatNormFloor));
  const T w = q[0], x = q[1], y = q[2], z = q[3];
  const T p[9] = {-(y * y + z * z), x * y - w * z, x * z + w * y,  x * y + w * z, -(x * x + z * z),
                       y * z - w * x,    x * z - w * y, y * z + w * x, -(x * x + y * y)};
  T gp = 0;
  for (int i = 0; i < 9; ++i) gp += gm[i] * p[i];
  const T ds = n2 > T(kQuatNormFloor) ? -s * s : T(0);  // ds/dq = -s^2 q
  gq[0] = s * (-z * gm[1] + y * gm[2] + z * gm[3] - x * gm[5] - y * gm[6] + x * gm[7]) + gp * ds * w;
  gq[1] = s * (y * gm[1] + z * gm[2] + y * gm[3] - 2 * x * gm[4] - w * gm[5] + z * gm[6] + w * gm[7] - 2 * x * gm[8]) +
          gp * ds * x;
  gq[2] = s * (-2 * y * gm[0] + x * gm[1] + w * gm[2] + x * gm[3] + z * gm[5] - w * gm[6] + z * gm[7] - 2 * y * gm[8]) +
          gp * ds * y;
  gq[3] = s * (-2 * z * gm[0] - w * gm[1] + x * gm[2] + w * gm[3] - 2 * z * gm[4] + y * gm[5] + x * gm[6] + y * gm[7]) +
          gp * ds * z;
}

}  // namespace mf::kernels
