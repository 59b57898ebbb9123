// Forward kinematics and its hand-written gradient on plain arrays (float or
// double), frame by frame: the kernels of the libtorch FK node
// (kinematics_torch.h) and of the Eigen runtime's FK (prior/runtime/kinematics.h),
// which therefore agree to the last bit. Torch-free. Layout per frame n:
// local and global rotations [J][9] (row-major 3x3 acting on column vectors),
// positions [J][3], root [3]; offsets [J][3] (row 0 unused); parents[j] < j,
// parents[0] = -1 (skeleton.h's conventions).
//   R_0 = L_0, p_0 = root;  R_j = R_par L_j, p_j = p_par + R_par o_j.
// Backward, children before parents:
//   gp_par += gp_j;  gR_par += gp_j o_j^T + gR_j L_j^T;
//   go_j = R_par^T gp_j;  gL_j = R_par^T gR_j;  gL_0 = gR_0;  g_root = gp_0.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace mf::kernels {

/// Frames [n0, n1) of local rotations L and root positions `root`: global
/// joint positions P and rotations R.
template <typename T>
void fk_forward(const T* L, const T* root, const T* o, const int* parents, int64_t J, int64_t n0, int64_t n1, T* P,
                T* R) {
  for (int64_t n = n0; n < n1; ++n) {
    const T* l = L + n * J * 9;
    T* r = R + n * J * 9;
    T* p = P + n * J * 3;
    std::copy(l, l + 9, r);
    std::copy(root + n * 3, root + n * 3 + 3, p);
    for (int64_t j = 1; j < J; ++j) {
      const T* a = r + parents[j] * 9;
      const T* b = l + j * 9;
      const T* oj = o + j * 3;
      const T* pp = p + parents[j] * 3;
      T* c = r + j * 9;
      for (int i = 0; i < 3; ++i) {
        for (int k = 0; k < 3; ++k) c[i * 3 + k] = a[i * 3] * b[k] + a[i * 3 + 1] * b[3 + k] + a[i * 3 + 2] * b[6 + k];
        p[j * 3 + i] = pp[i] + a[i * 3] * oj[0] + a[i * 3 + 1] * oj[1] + a[i * 3 + 2] * oj[2];
      }
    }
  }
}

/// The gradients of frames [n0, n1) from those of the positions gP and of the
/// global rotations gR (null: zero) at the forward's L and R: gL, gRoot and,
/// unless gO is null, per frame the offsets' gO [J][3] (row 0 zero). gp and gr
/// are scratch of J * 3 and J * 9 values.
template <typename T>
void fk_backward(const T* L, const T* o, const T* R, const T* gP, const T* gR, const int* parents, int64_t J,
                 int64_t n0, int64_t n1, T* gL, T* gRoot, T* gO, std::vector<T>& gp, std::vector<T>& gr) {
  for (int64_t n = n0; n < n1; ++n) {
    const T* l = L + n * J * 9;
    const T* r = R + n * J * 9;
    std::copy(gP + n * J * 3, gP + (n + 1) * J * 3, gp.begin());
    if (gR) {
      std::copy(gR + n * J * 9, gR + (n + 1) * J * 9, gr.begin());
    } else {
      std::fill(gr.begin(), gr.end(), T(0));
    }
    T* gl = gL + n * J * 9;
    T* go = gO ? gO + n * J * 3 : nullptr;
    if (go) std::fill(go, go + 3, T(0));
    for (int64_t j = J - 1; j >= 1; --j) {
      const int64_t q = parents[j];
      const T* a = r + q * 9;   // R_par
      const T* b = l + j * 9;   // L_j
      const T* oj = o + j * 3;
      const T* gpj = &gp[j * 3];
      const T* grj = &gr[j * 9];
      T* grq = &gr[q * 9];
      for (int i = 0; i < 3; ++i) {
        gp[q * 3 + i] += gpj[i];
        if (go) go[j * 3 + i] = a[i] * gpj[0] + a[3 + i] * gpj[1] + a[6 + i] * gpj[2];
        for (int k = 0; k < 3; ++k) {
          grq[i * 3 + k] += gpj[i] * oj[k] + grj[i * 3] * b[k * 3] + grj[i * 3 + 1] * b[k * 3 + 1] +
                            grj[i * 3 + 2] * b[k * 3 + 2];
          gl[j * 9 + i * 3 + k] = a[i] * grj[k] + a[3 + i] * grj[3 + k] + a[6 + i] * grj[6 + k];
        }
      }
    }
    std::copy(gr.begin(), gr.begin() + 9, gl);
    std::copy(gp.begin(), gp.begin() + 3, gRoot + n * 3);
  }
}

}  // namespace mf::kernels
