// Learned in-betweeners (the transformer models): networks that map a window
// with some known poses (full or partial) to a complete window in one forward
// pass. Two kinds implement the interface below:
//   "twostage"  Context Transformer + Detail Transformer (prior/inbetween/two_stage.h);
//               stage 0 is the context output, stage 1 the detail output
//   "citl"      CITL (prior/inbetween/citl.h); one stage
//   "keyframe"  KeyframeNet + RefineNet (prior/inbetween/keyframe_net.h),
//               trajectory-conditioned; stage 0 "keyframe" (the interpolated
//               predicted keyframes), stage 1 "refine"
// They are used standalone (methods "context", "detail", "citl", "keyframe", "refine") and as
// initialisers of the latent solvers (output -> prior encoders -> z0).
//
// Pose representation, shared by every kind, one vector per frame:
//   pose [B, T, D], D = J * 6 + 3: the 6D (first two columns of the rotation
//   matrix, column-major: r00 r10 r20 r01 r11 r21) of each joint's local
//   rotation, joint 0 being the root's rotation in the canonical frame, then
//   the root position (metres, canonical frame).
// Windows are canonical (prior/model/representation.h) at their first frame,
// which is always a known frame with a full pose. Windows shorter than
// `window` frames are padded at the end and the padding is marked invalid.
//
// Known values: known [B, T, J + 1]; known[b, t, j] = 1 when joint j's rotation
// is given at frame t (j < J) and known[b, t, J] = 1 when the root position is.
// Unknown entries of `pose` are zero and must not influence the output beyond
// the fact that they are unknown (models read pose * mask only).
#pragma once

#include <ATen/core/Tensor.h>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <cstdint>
#include <vector>

#include "prior/inbetween/inbetween_config.h"
#include "prior/inbetween/inbetweener_kinds.h"
#include "prior/model/representation.h"

namespace mf {

/// Pose features [B, T, J * 6 + 3] from local rotations [B, T, J, 3, 3] and
/// root positions [B, T, 3].
at::Tensor pose_features(const at::Tensor& local_rotations, const at::Tensor& root_positions);
/// The inverse: rotations are re-orthonormalised from the 6D (Gram-Schmidt).
void split_pose_features(const at::Tensor& pose, int num_joints, at::Tensor* local_rotations,
                         at::Tensor* root_positions);

/// Per-channel mask [..., J * 6 + 3] from known [..., J + 1]: each joint's flag
/// repeated over its 6 channels, the root-position flag over the last 3.
at::Tensor known_channel_mask(const at::Tensor& known, int num_joints);

struct InbetweenBatch {
  at::Tensor pose;   ///< [B, T, J * 6 + 3] raw (not normalised); zero where unknown
  at::Tensor known;  ///< [B, T, J + 1] float in {0, 1}
  at::Tensor valid;  ///< [B, T] float in {0, 1}; padding frames are 0
  /// Optional ground trajectory [B, T, 4] in the window's canonical frame
  /// (trajectory_features(): root x, z in metres, facing forward_x, forward_z),
  /// for kinds conditioned on it; undefined when the caller has none. Kinds
  /// that do not read it ignore it.
  at::Tensor trajectory;
};

struct InbetweenOutput {
  /// Raw pose features [B, T, D] after each stage; the last is the model's answer.
  std::vector<at::Tensor> stages;
  /// Foot contact logits [B, T, F] (rig().foot_joints order) when the model predicts them.
  at::Tensor contact_logits;
  /// Kinds that predict keyframes (kKeyframeKind, prior/inbetween/keyframe_net.h)
  /// also return: their own pose of every frame [B, T, D] (raw) before the
  /// keyframe selection, the keyframe score logits [B, T], and the frames the
  /// interpolation ran through [B, T] (float in {0, 1}: known frames, the last
  /// valid frame and the picked keyframes). Undefined for the other kinds.
  at::Tensor keyframe_poses;
  at::Tensor keyframe_logits;
  at::Tensor keyframes;
};

/// Z-score statistics of the pose features, measured on the training split.
/// Root positions are normalised like any other channel. A new model starts
/// with mean 0 and std 1.
struct InbetweenStats {
  at::Tensor pose_mean;  ///< [D]
  at::Tensor pose_std;   ///< [D]
};

class InbetweenModel {
 public:
  virtual ~InbetweenModel() = default;

  /// kTwoStageKind or kCitlKind.
  virtual std::string kind() const = 0;
  /// One name per output stage ({"context", "detail"} or {"citl"}).
  virtual std::vector<std::string> stage_names() const = 0;
  /// Hyperparameters as stored in the model file; a model made by
  /// make_inbetweener(kind(), hyperparameters(), rig()) has the same shapes.
  /// Always holds "window" (maximum frames) and "fps".
  virtual std::map<std::string, double> hyperparameters() const = 0;
  /// "context 4x128, detail 4x128, ..." for logs and the model card.
  virtual std::string describe() const = 0;

  /// One pass over a batch. Differentiable; normalisation with stats() is
  /// done inside.
  virtual InbetweenOutput forward(const InbetweenBatch& batch) const = 0;

  /// Every parameter by stable name (the model file's keys).
  virtual std::vector<std::pair<std::string, at::Tensor>> named_parameters() const = 0;
  virtual void train(bool on) = 0;

  const RigInfo& rig() const { return rig_; }
  InbetweenStats& stats() { return stats_; }
  const InbetweenStats& stats() const { return stats_; }
  int window() const;
  double fps() const;
  int pose_size() const { return rig_.num_joints() * 6 + 3; }
  std::vector<at::Tensor> parameters() const;
  int64_t num_parameters() const;
  void set_requires_grad(bool on);

 protected:
  explicit InbetweenModel(const RigInfo& rig);

  /// What forward() normalises with, after checking `batch` (pose
  /// [B, T, pose_size()] with 1 <= T <= `window`, known [B, T, J + 1], valid
  /// [B, T]; mf::InputError "<name>: ..." otherwise): stats() as float
  /// tensors [D] on the pose's device (zeros and ones when unset) and those
  /// tensor options.
  struct Normalisation {
    at::Tensor mean, scale;
    at::TensorOptions options;
  };
  Normalisation checked_normalisation(const InbetweenBatch& batch, int window, const std::string& name) const;

 private:
  RigInfo rig_;
  InbetweenStats stats_;
};

/// A freshly initialised model of `kind` (a product kind or a registered one)
/// with the given hyperparameters (missing ones take the kind's defaults). Throws
/// mf::InputError for an unknown kind or invalid hyperparameters.
std::unique_ptr<InbetweenModel> make_inbetweener(const std::string& kind,
                                                 const std::map<std::string, double>& hyperparameters,
                                                 const RigInfo& rig);

/// Makes a fresh model of one kind from its hyperparameters (missing ones take
/// the kind's defaults; InputError for invalid ones).
using InbetweenFactory =
    std::function<std::unique_ptr<InbetweenModel>(const std::map<std::string, double>&, const RigInfo&)>;
/// The number of parameters the factory of the same kind would allocate for
/// these hyperparameters and rig, computed without allocating them
/// (InputError for invalid hyperparameters).
using InbetweenParameterCount =
    std::function<int64_t(const std::map<std::string, double>&, const RigInfo&)>;

/// A product kind's libtorch network (inbetweener_kinds.h has the kinds):
/// how to make one, and its parameter count.
struct InbetweenNetwork {
  InbetweenFactory make;
  /// make's parameter count: a model file whose hyperparameters ask for more
  /// parameters than it holds values is refused before the network is built.
  InbetweenParameterCount count_parameters;
};
/// The network of the product kind `kind`, or null.
const InbetweenNetwork* find_inbetween_network(const std::string& kind);

/// Registers another kind for make_inbetweener / load_inbetweener only (tests
/// use it for tiny stand-in models); it gets no methods and no file name.
/// The product's kinds cannot be replaced.
void register_inbetweener_kind(const std::string& kind, InbetweenFactory factory);

/// The model file (prior/model/model_file.h container: same magic, version,
/// checksum; kind = the model's kind). Loading validates everything and throws
/// mf::InputError saying what is wrong, including a file of another kind.
/// Tensors: "stats.pose_mean", "stats.pose_std", then named_parameters().
/// A loaded model is in evaluation mode (train(false)); its parameters still
/// require grad (callers that only infer call set_requires_grad(false)).
void save_inbetweener(const InbetweenModel& model, const std::string& path);
std::unique_ptr<InbetweenModel> load_inbetweener(const std::string& path);
/// The same on bytes; `source` names the data in error messages.
std::vector<uint8_t> serialize_inbetweener(const InbetweenModel& model);
std::unique_ptr<InbetweenModel> deserialize_inbetweener(const uint8_t* data, size_t size, const std::string& source);

/// The three terms of inbetween_pose_loss (each already averaged over valid frames).
struct InbetweenLossParts {
  at::Tensor rotation;  ///< mean |d 6D| / max(std, 0.05) over the J * 6 channels
  at::Tensor position;  ///< mean |d p| over joints and axes, metres (FK, canonical frame)
  at::Tensor root;      ///< mean |d root position| over axes, metres
};

/// Training loss of one stage's output against the ground truth (both raw pose
/// features [B, T, D]), averaged over valid frames ([B, T]): L1 on the
/// normalised 6D rotations (std floored at 0.05 so that near-constant channels
/// do not dominate), L1 on FK joint positions in metres (global, canonical
/// frame) and L1 on the root position, weights 1, 1, 1. `parts` (optional)
/// receives the terms.
at::Tensor inbetween_pose_loss(const InbetweenModel& model, const at::Tensor& predicted, const at::Tensor& target,
                               const at::Tensor& valid, InbetweenLossParts* parts = nullptr);

}  // namespace mf
