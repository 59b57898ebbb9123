// KeyframeNet + RefineNet (prior/inbetween/keyframe_net.h) on Eigen, forward
// only. Made by inbetweener_runtime_from_bytes (inbetween_runtime.h), whose
// conventions it follows: stages "keyframe" (the picked keyframes
// interpolated) and "refine" (raw poses [T, D]), RefineNet's foot contact
// logits [T, F] and the keyframe outputs (InbetweenResult). Reads the
// window's trajectory when it has one, else makes one from the known values
// as the libtorch model does. The keyframes are picked by comparing score
// logits, which agree with libtorch's to float rounding: where two
// candidates' logits are that close (inputs alike on every frame), the two
// implementations may pick different frames, and the stages differ there.
#pragma once

#include <string>
#include <vector>

#include "prior/inbetween/inbetween_config.h"
#include "prior/runtime/inbetween_runtime.h"
#include "prior/runtime/transformer_blocks.h"

namespace mf::runtime {

class KeyframeRuntime final : public InbetweenerRuntime {
 public:
  /// Takes the network's weights ("keyframe.*", "refine.*") out of `w`.
  KeyframeRuntime(const KeyframeConfig& config, const RigInfo& rig, InbetweenNormalisation normalisation,
                  WeightReader& w);

  std::string kind() const override { return kKeyframeKind; }
  std::vector<std::string> stage_names() const override { return {"keyframe", "refine"}; }
  bool reads_trajectory() const override { return true; }
  int window() const override { return config_.window; }
  double fps() const override { return config_.fps; }
  void forward(const InbetweenWindow& in, InbetweenResult* out) const override;

 private:
  KeyframeConfig config_;
  TransformerStage keyframe_, refine_;
};

/// Poses [T, D] (raw) interpolated between the rows where `keys` holds
/// (interpolate_keyframes in keyframe_net.h): joint rotations by
/// shortest-path slerp, root positions linearly, the nearest key held
/// outside them.
MatrixRXf interpolate_keyframe_poses(const MatrixRXf& poses, const std::vector<bool>& keys, int joints);

/// The root's forward direction on the ground (forward_x, forward_z) of a
/// root rotation (row-major 3x3), as trajectory_features() of
/// prior/model/representation.h.
void ground_facing(const float* root, const RigInfo& rig, float* facing);

/// Trajectory rows [T, 4] (x, z, forward_x, forward_z) completed between the
/// known ones (interpolate_trajectory_rows in keyframe_net.h): x, z linearly
/// between the rows where `xz_known` holds, the facing between those where
/// `facing_known` holds, normalised; both held outside them.
MatrixRXf interpolate_trajectory_rows(const MatrixRXf& rows, const std::vector<bool>& xz_known,
                                      const std::vector<bool>& facing_known);

/// The trajectory [T, 4] the model makes without one (interpolated_trajectory
/// in keyframe_net.h) from raw poses [T, D] and known [T, J + 1] (already
/// multiplied by valid).
MatrixRXf interpolated_trajectory(const MatrixRXf& pose, const MatrixRXf& known, const RigInfo& rig);

}  // namespace mf::runtime
