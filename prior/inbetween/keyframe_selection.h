// KeyframeNet + RefineNet's torch-free rules (keyframe_net.h), shared by the
// libtorch network and the Eigen runtime (prior/runtime/keyframe_runtime.h):
// the adaptive keyframe selection of one window and the trajectory's layout.
#pragma once

namespace mf {

/// Trajectory channels: ground x, z, forward_x, forward_z.
constexpr int kTrajectorySize = 4;
/// Below this length an interpolated facing direction falls back to the
/// previous known one (interpolate_trajectory_rows in keyframe_net.h).
constexpr double kMinFacingNorm = 1e-3;

/// The keyframes of one window of T frames (select_keyframes() in
/// keyframe_net.h): from the score logits [T], the anchors [T] and the valid
/// frames [T], sets picked[t] = true at every picked frame (the caller clears
/// `picked` first). The spacings must satisfy 1 <= min_spacing and
/// 2 * min_spacing <= max_spacing (checked by the caller).
void select_window_keyframes(const float* logits, const bool* anchors, const bool* valid, int T, int min_spacing,
                             int max_spacing, bool* picked);

}  // namespace mf
