#include "tasks/latent/runtime_blend.h"

#include <algorithm>
#include <cmath>

#include "prior/motion/quaternion_kernels.h"
#include "tasks/latent/runtime_energy.h"

namespace mf {
namespace {

using runtime::MatrixRXf;

using kernels::MatrixQuat;
using kernels::quat_to_matrix;
using kernels::quat_to_matrix_vjp;
using kernels::Slerp;

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
      const Slerp<double> s(&key_quats_[(static_cast<size_t>(br.a) * J + j) * 4],
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
      kernels::slerp_vjp<double>(&key_quats_[a], &key_quats_[b], br.s, g_q, &g_key_quats[a], &g_key_quats[b]);
    }
  }
  for (int k = 0; k < K; ++k) {
    for (int j = 0; j < J; ++j) {
      const float* target = &p.key_rotations(k, j * 9);
      const float* raw = block(rotations, p.key_frames[k], j);
      double residual[9], g_residual[9] = {}, g_raw[9];
      matmul3(target, false, raw, true, residual);
      kernels::matrix_to_quat_vjp(residual, &g_key_quats[(static_cast<size_t>(k) * J + j) * 4], g_residual);
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
