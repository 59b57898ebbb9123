#include "tasks/latent/runtime_blend.h"

#include <algorithm>
#include <cmath>

#include "tasks/latent/runtime_energy.h"

namespace mf {
namespace {

using runtime::MatrixRXf;

// The squared-norm floor of rotations_torch.h's normalize_last and quat_to_matrix.
constexpr double kNormFloor = 1e-24;

double dot4(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]; }

// out += s * (g - (g.n) n): the gradient through a normalisation n = v s, s = 1/|v|.
void add_through_normalisation(const double* g, const double* n, double s, double* out) {
  const double p = dot4(g, n);
  for (int i = 0; i < 4; ++i) out[i] += s * (g[i] - p * n[i]);
}

// matrix_to_quat: 4 q_k q, the row of the candidate matrix built from the
// largest of 4w^2, 4x^2, 4y^2, 4z^2 (fs = 1 +- m00 +- m11 +- m22), over
// 2 sqrt(fs) (>= 2: no clamp), normalised, w made >= 0. The candidate matrix
// is symmetric; its off-diagonal entries are m[p] + sign m[q].
constexpr double kDiagonalSigns[4][3] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
struct OffDiagonal {
  int p, q;
  double sign;
};
constexpr OffDiagonal kOffDiagonal[4][4] = {{{0, 0, 0}, {7, 5, -1}, {2, 6, -1}, {3, 1, -1}},
                                            {{7, 5, -1}, {0, 0, 0}, {3, 1, 1}, {2, 6, 1}},
                                            {{2, 6, -1}, {3, 1, 1}, {0, 0, 0}, {5, 7, 1}},
                                            {{3, 1, -1}, {2, 6, 1}, {5, 7, 1}, {0, 0, 0}}};

struct MatrixQuat {
  int best = 0;
  double a, den, c[4], r[4], inv, sign, q[4];
  explicit MatrixQuat(const double* m) {
    double fs[4];
    for (int k = 0; k < 4; ++k)
      fs[k] = 1 + kDiagonalSigns[k][0] * m[0] + kDiagonalSigns[k][1] * m[4] + kDiagonalSigns[k][2] * m[8];
    for (int k = 1; k < 4; ++k) best = fs[k] > fs[best] ? k : best;
    a = std::sqrt(fs[best]);
    den = std::max(2 * a, 0.1);
    for (int i = 0; i < 4; ++i) {
      const OffDiagonal& o = kOffDiagonal[best][i];
      c[i] = i == best ? a * a : m[o.p] + o.sign * m[o.q];
      r[i] = c[i] / den;
    }
    inv = 1 / std::sqrt(std::max(dot4(r, r), kNormFloor));
    sign = r[0] * inv < 0 ? -1.0 : 1.0;
    for (int i = 0; i < 4; ++i) q[i] = sign * r[i] * inv;
  }
};

// gm [9] += the gradient with respect to m of <gq, matrix_to_quat(m)>.
void matrix_to_quat_vjp(const double* m, const double* gq, double* gm) {
  const MatrixQuat f(m);
  double g_signed[4], n[4], g_r[4] = {0, 0, 0, 0};
  for (int i = 0; i < 4; ++i) g_signed[i] = f.sign * gq[i], n[i] = f.r[i] * f.inv;
  add_through_normalisation(g_signed, n, f.inv, g_r);
  double g_den = 0;
  for (int i = 0; i < 4; ++i) g_den -= g_r[i] * f.c[i] / (f.den * f.den);
  const double g_a = (2 * f.a >= 0.1 ? 2 * g_den : 0.0) + 2 * f.a * g_r[f.best] / f.den;
  const double g_fs = g_a / (2 * f.a);
  for (int d = 0; d < 3; ++d) gm[d * 4] += kDiagonalSigns[f.best][d] * g_fs;
  for (int i = 0; i < 4; ++i) {
    if (i == f.best) continue;
    const OffDiagonal& o = kOffDiagonal[f.best][i];
    gm[o.p] += g_r[i] / f.den;
    gm[o.q] += o.sign * g_r[i] / f.den;
  }
}

// quat_slerp: both ends normalised, b flipped into a's hemisphere, NLERP
// above a cosine of 0.9995, the result normalised.
struct Slerp {
  double na, nb, a[4], b[4], bs[4], flip, dot, t, u, v, theta = 0, r[4], inv, q[4];
  bool near;
  Slerp(const double* qa, const double* qb, double t_) : t(t_) {
    na = 1 / std::sqrt(std::max(dot4(qa, qa), kNormFloor));
    nb = 1 / std::sqrt(std::max(dot4(qb, qb), kNormFloor));
    for (int i = 0; i < 4; ++i) a[i] = qa[i] * na, b[i] = qb[i] * nb;
    dot = dot4(a, b);
    flip = dot < 0 ? -1.0 : 1.0;
    for (int i = 0; i < 4; ++i) bs[i] = b[i] * flip;
    dot *= flip;
    near = dot > 0.9995;
    if (near) {
      u = 1 - t, v = t;
    } else {
      theta = std::acos(std::clamp(dot, -1.0, 1.0));
      u = std::sin((1 - t) * theta) / std::sin(theta);
      v = std::sin(t * theta) / std::sin(theta);
    }
    for (int i = 0; i < 4; ++i) r[i] = a[i] * u + bs[i] * v;
    inv = 1 / std::sqrt(std::max(dot4(r, r), kNormFloor));
    for (int i = 0; i < 4; ++i) q[i] = r[i] * inv;
  }
};

// g_qa, g_qb [4] += the gradients of <gq, slerp(qa, qb, t)>.
void slerp_vjp(const double* qa, const double* qb, double t, const double* gq, double* g_qa, double* g_qb) {
  const Slerp f(qa, qb, t);
  double g_r[4] = {0, 0, 0, 0}, g_a[4], g_bs[4], g_b[4];
  add_through_normalisation(gq, f.q, f.inv, g_r);
  for (int i = 0; i < 4; ++i) g_a[i] = g_r[i] * f.u, g_bs[i] = g_r[i] * f.v;
  if (!f.near) {
    const double sin_t = std::sin(f.theta), cos_t = std::cos(f.theta);
    const double du = ((1 - t) * std::cos((1 - t) * f.theta) * sin_t - std::sin((1 - t) * f.theta) * cos_t) /
                      (sin_t * sin_t);
    const double dv = (t * std::cos(t * f.theta) * sin_t - std::sin(t * f.theta) * cos_t) / (sin_t * sin_t);
    const double g_dot = (dot4(g_r, f.a) * du + dot4(g_r, f.bs) * dv) * (-1 / std::sqrt(1 - f.dot * f.dot));
    for (int i = 0; i < 4; ++i) g_a[i] += g_dot * f.bs[i], g_bs[i] += g_dot * f.a[i];
  }
  for (int i = 0; i < 4; ++i) g_b[i] = g_bs[i] * f.flip;
  add_through_normalisation(g_a, f.a, f.na, g_qa);
  add_through_normalisation(g_b, f.b, f.nb, g_qb);
}

// quat_to_matrix: I + s P(q), s = 2 / |q|^2 (row-major m [9]).
void quat_to_matrix(const double* q, double* m) {
  const double s = 2 / std::max(dot4(q, q), kNormFloor);
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  const double p[9] = {-(y * y + z * z), x * y - w * z, x * z + w * y,  x * y + w * z, -(x * x + z * z),
                       y * z - w * x,    x * z - w * y, y * z + w * x, -(x * x + y * y)};
  for (int i = 0; i < 9; ++i) m[i] = (i % 4 == 0 ? 1.0 : 0.0) + s * p[i];
}

// gq [4] = the gradient with respect to q of <gm, quat_to_matrix(q)>.
void quat_to_matrix_vjp(const double* q, const double* gm, double* gq) {
  const double n2 = dot4(q, q), s = 2 / std::max(n2, kNormFloor);
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  const double p[9] = {-(y * y + z * z), x * y - w * z, x * z + w * y,  x * y + w * z, -(x * x + z * z),
                       y * z - w * x,    x * z - w * y, y * z + w * x, -(x * x + y * y)};
  double gp = 0;
  for (int i = 0; i < 9; ++i) gp += gm[i] * p[i];
  const double ds = n2 > kNormFloor ? -s * s : 0.0;  // ds/dq = -s^2 q
  gq[0] = s * (-z * gm[1] + y * gm[2] + z * gm[3] - x * gm[5] - y * gm[6] + x * gm[7]) + gp * ds * w;
  gq[1] = s * (y * gm[1] + z * gm[2] + y * gm[3] - 2 * x * gm[4] - w * gm[5] + z * gm[6] + w * gm[7] - 2 * x * gm[8]) +
          gp * ds * x;
  gq[2] = s * (-2 * y * gm[0] + x * gm[1] + w * gm[2] + x * gm[3] + z * gm[5] - w * gm[6] + z * gm[7] - 2 * y * gm[8]) +
          gp * ds * y;
  gq[3] = s * (-2 * z * gm[0] - w * gm[1] + x * gm[2] + w * gm[3] - 2 * z * gm[4] + y * gm[5] + x * gm[6] + y * gm[7]) +
          gp * ds * z;
}

// c = a b (row-major 3x3; transposes as asked), in double.
template <typename A, typename B>
void matmul3(const A* a, bool ta, const B* b, bool tb, double* c) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double sum = 0;
      for (int k = 0; k < 3; ++k) sum += double(ta ? a[k * 3 + i] : a[i * 3 + k]) * double(tb ? b[j * 3 + k] : b[k * 3 + j]);
      c[i * 3 + j] = sum;
    }
}

// The 3x3 block of joint j in row r of a [T, J * 9] matrix.
const float* block(runtime::ConstMatrixRef m, int r, int j) { return m.data() + r * m.outerStride() + j * 9; }

}  // namespace

void RuntimeResidualBlend::brackets(const RuntimeWindowProblem& p, int J) {
  const int K = p.num_keys(), T = p.length;
  std::vector<char> on(K);
  std::vector<KeyBracket> series;
  joints_.resize(static_cast<size_t>(T) * J);
  for (int j = 0; j < J; ++j) {
    for (int k = 0; k < K; ++k) on[k] = p.key_rotation_mask(k, j) > 0;
    key_brackets(p.key_frames, on, T, &series);
    for (int t = 0; t < T; ++t) joints_[static_cast<size_t>(t) * J + j] = series[t];
  }
  for (int k = 0; k < K; ++k) on[k] = p.key_root_mask[k] > 0;
  key_brackets(p.key_frames, on, T, &root_);
}

void RuntimeResidualBlend::forward(const RuntimeWindowProblem& p, runtime::ConstMatrixRef rotations,
                                   runtime::ConstMatrixRef path, MatrixRXf* out_rotations, MatrixRXf* out_path) {
  const int J = static_cast<int>(rotations.cols() / 9), T = p.length, K = p.num_keys();
  brackets(p, J);
  blend_rotations(p, rotations, out_rotations);
  MatrixRXf d(K, 3);
  for (int k = 0; k < K; ++k) d.row(k) = p.key_root.row(k) - path.row(p.key_frames[k]);
  *out_path = path;
  for (int t = 0; t < T; ++t) {
    const KeyBracket& br = root_[t];
    if (br.has) out_path->row(t) += d.row(br.a) * (1.0f - br.s) + d.row(br.b) * br.s;
  }
}

// The keys' residual quaternions, their blend at every (frame, joint) a key
// constrains, and the blended rotations.
void RuntimeResidualBlend::blend_rotations(const RuntimeWindowProblem& p, runtime::ConstMatrixRef rotations,
                                           MatrixRXf* out_rotations) {
  const int J = static_cast<int>(rotations.cols() / 9), T = p.length, K = p.num_keys();
  key_quats_.resize(static_cast<size_t>(K) * J * 4);
  for (int k = 0; k < K; ++k) {
    for (int j = 0; j < J; ++j) {
      double residual[9];
      matmul3(&p.key_rotations(k, j * 9), false, block(rotations, p.key_frames[k], j), true, residual);
      const MatrixQuat mq(residual);
      std::copy(mq.q, mq.q + 4, &key_quats_[(static_cast<size_t>(k) * J + j) * 4]);
    }
  }
  quats_.assign(static_cast<size_t>(T) * J * 4, 0.0);
  *out_rotations = rotations;
  for (int t = 0; t < T; ++t) {
    for (int j = 0; j < J; ++j) {
      const KeyBracket& br = joints_[static_cast<size_t>(t) * J + j];
      if (!br.has) continue;
      double* q = &quats_[(static_cast<size_t>(t) * J + j) * 4];
      const Slerp s(&key_quats_[(static_cast<size_t>(br.a) * J + j) * 4],
                    &key_quats_[(static_cast<size_t>(br.b) * J + j) * 4], br.s);
      std::copy(s.q, s.q + 4, q);
      double m[9], out[9];
      quat_to_matrix(q, m);
      matmul3(m, false, block(rotations, t, j), false, out);
      for (int i = 0; i < 9; ++i) (*out_rotations)(t, j * 9 + i) = static_cast<float>(out[i]);
    }
  }
}

void RuntimeResidualBlend::vjp(const RuntimeWindowProblem& p, runtime::ConstMatrixRef rotations,
                               runtime::ConstMatrixRef g_out_rotations, runtime::ConstMatrixRef g_out_path,
                               MatrixRXf* g_rotations, MatrixRXf* g_path) const {
  const int J = static_cast<int>(rotations.cols() / 9), T = p.length, K = p.num_keys();
  std::vector<double> g_key_quats(static_cast<size_t>(K) * J * 4, 0.0);
  for (int t = 0; t < T; ++t) {
    for (int j = 0; j < J; ++j) {
      const KeyBracket& br = joints_[static_cast<size_t>(t) * J + j];
      const float* g_out = block(g_out_rotations, t, j);
      if (!br.has) {
        for (int i = 0; i < 9; ++i) (*g_rotations)(t, j * 9 + i) += g_out[i];
        continue;
      }
      const double* q = &quats_[(static_cast<size_t>(t) * J + j) * 4];
      double m[9], g_rot[9], g_m[9], g_q[4];
      quat_to_matrix(q, m);
      matmul3(m, true, g_out, false, g_rot);                 // out = M R: g_R = M^T g
      matmul3(g_out, false, block(rotations, t, j), true, g_m);  // g_M = g R^T
      for (int i = 0; i < 9; ++i) (*g_rotations)(t, j * 9 + i) += static_cast<float>(g_rot[i]);
      quat_to_matrix_vjp(q, g_m, g_q);
      const size_t a = (static_cast<size_t>(br.a) * J + j) * 4, b = (static_cast<size_t>(br.b) * J + j) * 4;
      slerp_vjp(&key_quats_[a], &key_quats_[b], br.s, g_q, &g_key_quats[a], &g_key_quats[b]);
    }
  }
  for (int k = 0; k < K; ++k) {
    for (int j = 0; j < J; ++j) {
      const float* target = &p.key_rotations(k, j * 9);
      const float* raw = block(rotations, p.key_frames[k], j);
      double residual[9], g_residual[9] = {}, g_raw[9];
      matmul3(target, false, raw, true, residual);
      matrix_to_quat_vjp(residual, &g_key_quats[(static_cast<size_t>(k) * J + j) * 4], g_residual);
      matmul3(g_residual, true, target, false, g_raw);  // residual = A B^T: g_B = G^T A
      for (int i = 0; i < 9; ++i) (*g_rotations)(p.key_frames[k], j * 9 + i) += static_cast<float>(g_raw[i]);
    }
  }
  *g_path += g_out_path;
  for (int t = 0; t < T; ++t) {
    const KeyBracket& br = root_[t];
    if (!br.has) continue;
    g_path->row(p.key_frames[br.a]) -= g_out_path.row(t) * (1.0f - br.s);
    g_path->row(p.key_frames[br.b]) -= g_out_path.row(t) * br.s;
  }
}

}  // namespace mf
