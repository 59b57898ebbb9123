// The transformer in-betweeners (prior/inbetween/inbetweener.h) on Eigen,
// without libtorch: the forward pass of every product kind ("twostage",
// "citl", "keyframe"), loaded from the same model file as the libtorch
// networks (the kind and the hyperparameters from the file; a file with a
// tensor the architecture lacks is refused), for one window at a time (the
// libtorch batch with B = 1). tests/runtime_inbetween_equivalence_test.cc
// holds every stage's output to the libtorch networks' (within 1e-5 relative
// to the largest value).
//
// Shapes: row-major float matrices with one row per frame (MatrixRXf); J
// joints and F feet of the model's rig (rig()), D = J * 6 + 3 pose values per
// frame: per joint the 6D of its local rotation (r00 r10 r20 r01 r11 r21; the
// root's in the window's canonical frame), then the root position (metres,
// canonical frame), as InbetweenBatch::pose. Forward only: no gradients.
// A loaded runtime is immutable and may be shared between threads: forward()
// is const and allocates its buffers per call, on the calling thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "prior/model/rig_info.h"
#include "prior/runtime/tensor_ops.h"

namespace mf::runtime {

/// One window, InbetweenBatch's tensors without the batch dimension.
struct InbetweenWindow {
  MatrixRXf pose;         ///< [T, D] raw (not normalised); values where unknown are ignored
  MatrixRXf known;        ///< [T, J + 1] in {0, 1}: joint j's rotation (j < J), the root position (J)
  Eigen::VectorXf valid;  ///< [T] in {0, 1}; padding frames (at the end) are 0
  /// [T, 4] ground trajectory in the canonical frame (root x, z in metres,
  /// facing forward_x, forward_z) for kinds that read it (reads_trajectory());
  /// empty (0 rows) when the caller has none. Other kinds ignore it.
  MatrixRXf trajectory;
};

/// InbetweenOutput for one window.
struct InbetweenResult {
  /// Raw pose [T, D] after each stage (stage_names() order); the last is the answer.
  std::vector<MatrixRXf> stages;
  /// Foot contact logits [T, F] (rig().foot_joints order) when the kind
  /// predicts them, else empty.
  MatrixRXf contact_logits;
  /// Keyframe kind only (else empty): KeyframeNet's own pose of every frame
  /// [T, D] (raw), its keyframe score logits [T], and the frames the
  /// interpolation ran through [T] (1: known frames, the last valid frame,
  /// the picked keyframes; 0 elsewhere and on padding).
  MatrixRXf keyframe_poses;
  Eigen::VectorXf keyframe_logits;
  Eigen::VectorXf keyframes;
};

/// The statistics the pose is normalised with: stats.pose_mean and
/// stats.pose_std of the file, the std floored at 1e-6 (as libtorch's forward).
struct InbetweenNormalisation {
  RowVectorXf mean;   ///< [D]
  RowVectorXf scale;  ///< [D]
};

class InbetweenerRuntime {
 public:
  virtual ~InbetweenerRuntime() = default;

  /// The model file's kind: "twostage", "citl" or "keyframe".
  virtual std::string kind() const = 0;
  /// One name per output stage, as InbetweenModel::stage_names().
  virtual std::vector<std::string> stage_names() const = 0;
  /// Whether forward() reads InbetweenWindow::trajectory.
  virtual bool reads_trajectory() const { return false; }
  /// The maximum frames of a window and the frame rate of the training data.
  virtual int window() const = 0;
  virtual double fps() const = 0;

  /// One pass over a window with 1 <= T <= window() frames (InputError for
  /// other shapes, naming the kind); `out` is overwritten.
  virtual void forward(const InbetweenWindow& in, InbetweenResult* out) const = 0;

  /// "twostage, window 41 at 30 fps": for logs and benchmark headers.
  std::string describe() const;

  const RigInfo& rig() const { return rig_; }
  const InbetweenNormalisation& normalisation() const { return normalisation_; }
  int pose_size() const { return rig_.num_joints() * 6 + 3; }

 protected:
  InbetweenerRuntime(const RigInfo& rig, InbetweenNormalisation normalisation);
  /// Checks `in` against the rig and `window` (InputError "<name>: ..." as
  /// the libtorch models word it) and returns T.
  int checked_frames(const InbetweenWindow& in, int window, const std::string& name) const;

 private:
  RigInfo rig_;
  InbetweenNormalisation normalisation_;
};

/// The in-betweener of a model file's bytes; InputError naming `source` for a
/// file of another kind, invalid hyperparameters, a missing or misshapen
/// tensor, or a tensor the architecture does not have.
std::unique_ptr<const InbetweenerRuntime> inbetweener_runtime_from_bytes(const uint8_t* data, size_t size,
                                                                         const std::string& source);
/// The in-betweener of the model file at `path`.
std::unique_ptr<const InbetweenerRuntime> load_inbetweener_runtime(const std::string& path);

}  // namespace mf::runtime
