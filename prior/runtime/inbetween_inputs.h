// What the in-betweeners' forward passes make of an InbetweenWindow before
// their networks run (the masking and normalisation at the top of the
// libtorch forwards in prior/inbetween/), shared by the Eigen runtime's kinds.
// Internal to prior/runtime/.
#pragma once

#include <vector>

#include "prior/runtime/inbetween_runtime.h"

namespace mf::runtime {

/// Per-frame flags of a column of values: value > 0.5.
std::vector<bool> flags_of(const Eigen::Ref<const Eigen::VectorXf>& values);

/// The window's known values as the networks see them.
struct MaskedWindow {
  MatrixRXf known;                  ///< [T, J + 1]: known * valid
  MatrixRXf channel_known;          ///< [T, D] in {0, 1}: each joint's flag on its 6 channels, the root's on 3
  std::vector<bool> key;            ///< [T]: a known value at the frame
  std::vector<bool> valid;          ///< [T]
  MatrixRXf normalised;             ///< [T, D]: (pose - mean) / scale, everywhere
};
MaskedWindow masked_window(const InbetweenWindow& in, const InbetweenNormalisation& n, int joints);

/// The networks' pose input x [T, D] (two_stage.h, keyframe_net.h): the
/// normalised rotation channels where known (zero elsewhere), and the root
/// position interpolated between the frames where it is known, then normalised.
MatrixRXf masked_pose_input(const InbetweenWindow& in, const MaskedWindow& m, const InbetweenNormalisation& n,
                            int joints);

/// x where channel_known, else y (both [T, D]).
MatrixRXf where_known(const MatrixRXf& channel_known, const MatrixRXf& x, const MatrixRXf& y);

/// Raw values of normalised ones: x * scale + mean, row by row.
MatrixRXf denormalised(const MatrixRXf& x, const InbetweenNormalisation& n);

/// [a, b] side by side (rows must agree).
MatrixRXf concat_columns(const MatrixRXf& a, const MatrixRXf& b);

}  // namespace mf::runtime
