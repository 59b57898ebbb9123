// Canonical windows without tensors: the rigid ground transform that makes a
// window of a motion canonical (prior/model/representation.h defines the
// canonical frame and the heading), a window's local rotations and root
// positions in that frame as row-major matrices, and the way back into a
// motion. representation.h builds its tensors on these; the Eigen runtime's
// callers use them directly.
#pragma once

#include <Eigen/Core>

#include "prior/model/rig_info.h"
#include "prior/motion/motion.h"

namespace mf {

/// The rigid ground transform that made a window canonical: world = R_y(yaw) * canonical + (x, 0, z).
struct GroundTransform {
  double yaw = 0.0;
  double x = 0.0;
  double z = 0.0;
};

/// The canonical transform of frame `anchor_frame`: the root's ground position
/// and heading yaw there (yaw 0 when the root's forward axis is vertical).
GroundTransform canonical_transform(const Motion& motion, int anchor_frame, const RigInfo& rig);

/// Motion frames [begin, begin + length) in the canonical frame of frame
/// `begin + anchor`, float, one row per frame: each joint's local rotation as
/// 9 values (row-major 3x3; joint 0's is the root's rotation in the canonical
/// frame) and the root position (metres).
struct WindowMatrices {
  using Rows = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  Rows local_rotations;  ///< [T, J * 9]
  Rows root_positions;   ///< [T, 3]
};
/// Throws InputError when the window or its anchor lies outside the motion.
WindowMatrices window_matrices(const Motion& motion, int begin, int length, const RigInfo& rig, int anchor = 0);

/// Writes a canonical window (rotations [T, J * 9] as window_matrices(), root
/// positions [T, 3], double) back into `motion` frames [begin, begin + T),
/// undoing `transform`. Throws InputError when it does not fit the motion.
void write_window(const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>& local_rotations,
                  const Eigen::Ref<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>& root_positions,
                  const GroundTransform& transform, Motion* motion, int begin);

}  // namespace mf
