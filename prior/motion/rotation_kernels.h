// Per-element kernels of the rotation conversions the prior differentiates,
// with their hand-written gradients, on plain arrays (float or double): the
// 6D Gram-Schmidt, the geodesic angle of two rotation matrices and the
// heading of a root rotation. Torch-free: the libtorch autograd nodes
// (rotations_torch.h, representation.h heading_rotation) and the Eigen runtime
// (prior/runtime/rotations.h) run these same functions, so the two agree to
// the last bit on the same inputs. Matrices are row-major 3x3 (9 values)
// acting on column vectors; 6D = (m00, m10, m20, m01, m11, m21) as in
// rotations.h.
#pragma once

#include <cmath>

namespace mf::kernels {

template <typename T>
T dot3(const T* a, const T* b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// out += a x b.
template <typename T>
void cross_add(const T* a, const T* b, T* out) {
  out[0] += a[1] * b[2] - a[2] * b[1];
  out[1] += a[2] * b[0] - a[0] * b[2];
  out[2] += a[0] * b[1] - a[1] * b[0];
}

/// The squared-norm floor of the 6D Gram-Schmidt's two normalisations (a
/// clamped norm keeps the gradient finite for a zero half).
constexpr double kSixdNormFloor = 1e-24;

/// Gram-Schmidt of one 6-vector (a1, a2):
///   b1 = a1 r1, r1 = 1/|a1|;  u = a2 - (b1.a2) b1;  b2 = u r2, r2 = 1/|u|;  b3 = b1 x b2.
template <typename T>
struct SixdFrame {
  T a1[3], a2[3], b1[3], b2[3], b3[3], u[3], r1, r2, d;
  bool clamp1, clamp2;
  explicit SixdFrame(const T* x) {
    for (int i = 0; i < 3; ++i) a1[i] = x[i], a2[i] = x[3 + i];
    const T n1 = a1[0] * a1[0] + a1[1] * a1[1] + a1[2] * a1[2];
    clamp1 = n1 < T(kSixdNormFloor);
    r1 = T(1) / std::sqrt(clamp1 ? T(kSixdNormFloor) : n1);
    for (int i = 0; i < 3; ++i) b1[i] = a1[i] * r1;
    d = b1[0] * a2[0] + b1[1] * a2[1] + b1[2] * a2[2];
    for (int i = 0; i < 3; ++i) u[i] = a2[i] - d * b1[i];
    const T n2 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    clamp2 = n2 < T(kSixdNormFloor);
    r2 = T(1) / std::sqrt(clamp2 ? T(kSixdNormFloor) : n2);
    for (int i = 0; i < 3; ++i) b2[i] = u[i] * r2;
    b3[0] = b1[1] * b2[2] - b1[2] * b2[1];
    b3[1] = b1[2] * b2[0] - b1[0] * b2[2];
    b3[2] = b1[0] * b2[1] - b1[1] * b2[0];
  }
};

/// The rotation matrix m (columns b1, b2, b3) of the 6D x.
template <typename T>
void sixd_to_matrix(const T* x, T* m) {
  const SixdFrame<T> f(x);
  for (int i = 0; i < 3; ++i) m[i * 3] = f.b1[i], m[i * 3 + 1] = f.b2[i], m[i * 3 + 2] = f.b3[i];
}

/// The gradient gd [6] of an energy with respect to the 6D x from its gradient
/// G [9] with respect to sixd_to_matrix(x):
///   g1 += b2 x g3, g2 += g3 x b1;  gu = r2 (g2 - (g2.b2) b2);
///   ga2 = gu - (gu.b1) b1;  g1 += -(b1.a2) gu - (gu.b1) a2;  ga1 = r1 (g1 - (g1.b1) b1)
/// (a clamped norm passes g r unprojected, as clamp_min's zero gradient does).
template <typename T>
void sixd_to_matrix_vjp(const T* x, const T* G, T* gd) {
  const SixdFrame<T> f(x);
  T g1[3], g2[3], g3[3], gu[3];
  for (int i = 0; i < 3; ++i) g1[i] = G[i * 3], g2[i] = G[i * 3 + 1], g3[i] = G[i * 3 + 2];
  cross_add(f.b2, g3, g1);
  cross_add(g3, f.b1, g2);
  const T p2 = f.clamp2 ? T(0) : dot3(g2, f.b2);
  for (int i = 0; i < 3; ++i) gu[i] = f.r2 * (g2[i] - p2 * f.b2[i]);
  const T ub = dot3(gu, f.b1);
  for (int i = 0; i < 3; ++i) {
    gd[3 + i] = gu[i] - ub * f.b1[i];
    g1[i] += -f.d * gu[i] - ub * f.a2[i];
  }
  const T p1 = f.clamp1 ? T(0) : dot3(g1, f.b1);
  for (int i = 0; i < 3; ++i) gd[i] = f.r1 * (g1[i] - p1 * f.b1[i]);
}

/// The relative rotation R = A^T B of two rotation matrices, its skew part
/// v = (R21 - R12, R02 - R20, R10 - R01) / 2 = sin(angle) axis, s = |v| and
/// c = (trace R - 1) / 2 = cos(angle): the angle is atan2(s, c), which keeps
/// float precision near 0 and pi.
template <typename T>
struct GeodesicPair {
  T R[9], v[3], s, c;
  GeodesicPair(const T* A, const T* B) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) R[i * 3 + j] = A[i] * B[j] + A[3 + i] * B[3 + j] + A[6 + i] * B[6 + j];
    v[0] = T(0.5) * (R[7] - R[5]);
    v[1] = T(0.5) * (R[2] - R[6]);
    v[2] = T(0.5) * (R[3] - R[1]);
    s = std::sqrt(dot3(v, v));
    c = T(0.5) * (R[0] + R[4] + R[8] - T(1));
  }
};

/// The geodesic angle (radians) between rotation matrices A and B.
template <typename T>
T geodesic_angle(const T* A, const T* B) {
  const GeodesicPair<T> p(A, B);
  return std::atan2(p.s, p.c);
}

/// The gradients of g * geodesic_angle(A, B) with respect to A (gA [9]) and B
/// (gB [9]); either may be null. With d = s^2 + c^2, g_s = g c / d,
/// g_c = -g s / d, G = dL/dR = (g_c / 2) I plus (g_s / 2) v/s scattered to the
/// skew entries (zero where s = 0: a subgradient); gA = B G^T, gB = A G.
template <typename T>
void geodesic_angle_vjp(const T* A, const T* B, T g, T* gA, T* gB) {
  const GeodesicPair<T> p(A, B);
  const T d = p.s * p.s + p.c * p.c;
  const T gs = d > 0 ? g * p.c / d : T(0);
  const T gc = d > 0 ? -g * p.s / d : T(0);
  const T k = p.s > 0 ? T(0.5) * gs / p.s : T(0);
  const T h = T(0.5) * gc;
  const T x = k * p.v[0], y = k * p.v[1], z = k * p.v[2];
  const T G[9] = {h, -z, y, z, h, -x, -y, x, h};
  if (gA) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        gA[i * 3 + j] = B[i * 3] * G[j * 3] + B[i * 3 + 1] * G[j * 3 + 1] + B[i * 3 + 2] * G[j * 3 + 2];
  }
  if (gB) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) gB[i * 3 + j] = A[i * 3] * G[j] + A[i * 3 + 1] * G[3 + j] + A[i * 3 + 2] * G[6 + j];
  }
}

/// The regulariser of the heading's normalisation (prior/model/representation.h).
constexpr double kHeadingEps = 1e-12;

/// The heading H = R_y(yaw) of the root rotation r for the root-local forward
/// axis w: f = r w, n = sqrt(fx^2 + fz^2 + eps), (s, c) = (fx, fz) / n,
/// H = [[c, 0, s], [0, 1, 0], [-s, 0, c]].
template <typename T>
void heading_rotation(const T* r, const T* w, T* h) {
  const T fx = r[0] * w[0] + r[1] * w[1] + r[2] * w[2];
  const T fz = r[6] * w[0] + r[7] * w[1] + r[8] * w[2];
  const T inv = T(1) / std::sqrt(fx * fx + fz * fz + T(kHeadingEps));
  const T s = fx * inv, c = fz * inv;
  h[0] = c, h[1] = 0, h[2] = s;
  h[3] = 0, h[4] = 1, h[5] = 0;
  h[6] = -s, h[7] = 0, h[8] = c;
}

/// The gradient gr [9] with respect to r from gh [9] with respect to
/// heading_rotation(r, w): g_s = G02 - G20, g_c = G00 + G22;
/// g_fx = (g_s (fz^2 + eps) - g_c fx fz) / n^3, g_fz = (g_c (fx^2 + eps) - g_s fx fz) / n^3;
/// row 0 = g_fx w^T, row 2 = g_fz w^T, row 1 = 0.
template <typename T>
void heading_rotation_vjp(const T* r, const T* w, const T* gh, T* gr) {
  const T eps = T(kHeadingEps);
  const T fx = r[0] * w[0] + r[1] * w[1] + r[2] * w[2];
  const T fz = r[6] * w[0] + r[7] * w[1] + r[8] * w[2];
  const T n2 = fx * fx + fz * fz + eps;
  const T inv3 = T(1) / (n2 * std::sqrt(n2));
  const T gs = gh[2] - gh[6], gc = gh[0] + gh[8];
  const T gfx = (gs * (fz * fz + eps) - gc * fx * fz) * inv3;
  const T gfz = (gc * (fx * fx + eps) - gs * fx * fz) * inv3;
  for (int k = 0; k < 3; ++k) gr[k] = gfx * w[k], gr[3 + k] = 0, gr[6 + k] = gfz * w[k];
}

}  // namespace mf::kernels
