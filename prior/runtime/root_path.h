// The root path of one dense decoded window on Eigen, without libtorch: the
// global motion predictor's inputs (gmp_inputs() of prior/model/representation.h)
// and the forward-Euler integration of its outputs (NemfModel::root_positions()
// in prior/model/nemf.h). Shared by the latent energy
// (tasks/latent/runtime_energy.h, which also writes out their gradients) and
// the codec (tasks/latent/prior_codec.h). Row-major float, one row per frame.
#pragma once

#include <Eigen/Core>

#include "prior/runtime/tensor_ops.h"

namespace mf::runtime {

/// The GMP's raw inputs of a window's rotations [T, J * 9] (local, joint 0's
/// in the canonical frame) and FK positions [T, J * 3] (root at the origin)
/// for the root-local forward axis `root_forward`: per frame the heading H of
/// the root rotation [T, 9] (row-major 3x3, `headings`, resized) and in
/// `inputs` [T, J * 3 + 6] (resized) the joints' positions with the heading
/// removed (H^T p), then the 6D of H^T R_root (its first two columns).
void gmp_inputs(ConstMatrixRef rotations, ConstMatrixRef positions, const Eigen::Vector3f& root_forward,
                MatrixRXf* headings, MatrixRXf* inputs);

/// The root path [T, 3] (resized) of the GMP's outputs `gmp_out` [T, >= 4]
/// (heading-frame velocity in m/s, height in m) at `fps`: each frame's
/// velocity turned by its heading ([T, 9], as gmp_inputs()) and integrated by
/// forward Euler from the origin on the ground (summed in double, as
/// libtorch's float cumsum does); the height as predicted.
void integrate_root_path(ConstMatrixRef headings, ConstMatrixRef gmp_out, double fps, MatrixRXf* path);

}  // namespace mf::runtime
