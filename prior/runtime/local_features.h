// The NeMF encoders' input on Eigen, forward only: local_features() of
// prior/model/representation.h for one canonical window, so that a window is
// encoded without libtorch (NemfRuntime::encode_features).
// tests/runtime_equivalence_test.cc holds the features and the codes on them
// to libtorch's.
#pragma once

#include <Eigen/Core>

#include "prior/runtime/kinematics.h"
#include "prior/runtime/tensor_ops.h"

namespace mf::runtime {

/// The joints' positions relative to the root in the heading frame
/// (heading_relative_positions() of prior/model/representation.h) of local
/// rotations [T, J * 9]: FK from the origin with the heading removed from
/// the root's rotation. `positions` [T, J * 3] and the global rotations
/// `globals` [T, J * 9] (with the heading removed), both resized.
void heading_free_positions(const Kinematics& kinematics, ConstMatrixRef local_rotations,
                            const Eigen::Vector3f& root_forward, MatrixRXf* positions, MatrixRXf* globals);

/// The local-motion features of a window's local rotations [T, J * 9]
/// (canonical frame; joint 0's is the root's rotation, row-major 3x3) at
/// `fps` frames per second, with the rig's root forward axis: `features`
/// [T, J * 15], per joint its position relative to the root in the heading
/// frame (3, metres), their velocity (3, central differences, one-sided at the
/// ends, per second), the 6D of its global rotation with the heading removed
/// (6) and its angular velocity (3, rad/s); `root6d` [T, 6] the 6D of the
/// root's rotation. Both resized; T >= 1 (one frame has zero velocities).
void local_features(const Kinematics& kinematics, ConstMatrixRef local_rotations, const Eigen::Vector3f& root_forward,
                    double fps, MatrixRXf* features, MatrixRXf* root6d);

}  // namespace mf::runtime
