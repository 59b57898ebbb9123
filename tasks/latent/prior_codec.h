// The prior as a codec: a motion of any length and frame rate encoded into a
// sequence of window latents, and latents decoded at any times into a motion at
// any frame rate. Resampling with the prior builds on both.
//
// Time. A window holds NemfConfig::window frames at the model's frame rate
// (NemfConfig::fps, "model frames"). Times handed to the decoder are seconds
// from the motion's first frame; time t is model-frame position s = t * model fps.
//
// Encoding (encode_motion):
//   1. A motion whose fps differs from the model's is first resampled to the
//      model's rate by interpolation (root LERP, rotation SLERP; see
//      resample_interpolate() in tasks/constraints/interpolation_fill.h) over the same time span; the
//      last model frame is the first at or past the input's last frame time
//      (positions past the last input frame hold it). A motion already at the
//      model's rate (within 1e-5 relative) is used as it is.
//   2. The model-rate sequence of N frames is cut into windows (window_starts()
//      of tasks/latent/windows.h):
//      N <= window: one short window [0, N); the encoder masks the missing frames
//      (see nemf.h, "Short clips"). Otherwise windows of exactly `window` frames
//      start at 0, hop, 2 hop, ... while they end before the last frame, and one
//      more window is aligned to the end (start N - window). The hop defaults to
//      window / 2, so every frame is covered by at least two windows except near
//      the clip's ends, and the end window may overlap its predecessor by more.
//   3. Each window is made canonical at its first frame
//      (prior/model/canonical_window.h: window_matrices with anchor 0); the
//      window keeps that GroundTransform and its start frame. The latent is
//      the encoders' mean (mu_l, mu_g; NemfRuntime::encode_rotations):
//      encoding is deterministic.
//
// Decoding (decode_motion / decode_times):
//   * Each window is decoded at the local positions s - start that fall inside
//     it ([0, length - 1]); positions outside every window are clamped to the
//     sequence ([0, N - 1]), i.e. the ends hold.
//   * Blending (blend_weights()): window k's weight at position s is a product
//     of a raised-cosine ramp-in over its overlap with window k - 1
//     (0.5 - 0.5 cos(pi u), u from 0 at its start to 1 at the end of window
//     k - 1) and a raised-cosine ramp-out over its overlap with window k + 1
//     (1 at the start of window k + 1 down to 0 at its own last frame); the
//     first window has no ramp-in, the last no ramp-out. The weights are
//     normalised to sum to one. Where only two windows overlap the two ramps are
//     complementary (sin^2 + cos^2), so the normalisation changes nothing there.
//   * Rotations: normalised weighted sum of the windows' quaternions, each
//     flipped into the hemisphere of the sum so far (a first-order weighted
//     quaternion mean; the windows agree closely where they overlap). Root orientation (joint 0) is blended in the world frame, after
//     undoing each window's GroundTransform. Positions: weighted sum.
//   * Root translation, RootSource::kPrior: per window, the model is decoded
//     densely at the window's model frames, the global motion predictor
//     (GmpUse::Default) gives heading-frame velocity and height, and
//     forward-Euler integration from the canonical origin
//     (prior/runtime/root_path.h, as NemfModel::root_positions) gives the
//     window's root path; its GroundTransform then places the path so that it starts at
//     the input's root ground position (x, z) at the window's first frame and
//     with the input's heading there (height comes from the predictor, not the
//     input). Between model frames the path follows a uniform Catmull-Rom
//     spline through the model frames (C1, so no velocity kinks at 240 fps). Every
//     window thus drifts only over its own length, never accumulating over the
//     clip. RootSource::kInput: the input's root positions interpolated linearly
//     at the requested times (kept in EncodedMotion::source_*).
//
// Runtime: the networks run on the Eigen runtime (prior/runtime/nemf_runtime.h),
// without libtorch, one window at a time on the calling thread (its products
// on the BLAS's threads). The runtime is only read: one runtime can serve
// several threads. tests/runtime_codec_equivalence_test.cc holds the codec to
// the libtorch networks (NemfModel) through CodecPrior.
//
// Errors: mf::InputError when the motion is invalid, has fewer than 2 frames, or
// its skeleton does not match the model's rig (joint names and parents), when an
// fps is not finite and positive, a frame count is negative, times are not
// finite, or an EncodedMotion is inconsistent with the model.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "prior/model/canonical_window.h"
#include "prior/model/nemf_config.h"
#include "prior/model/rig_info.h"
#include "prior/motion/motion.h"
#include "tasks/context/task_context.h"
#include "tasks/latent/windows.h"  // window_starts()

namespace mf {

namespace runtime {
class NemfRuntime;
}

struct CodecOptions {
  /// Model frames between window starts; 0 means window / 2. Must lie in
  /// [1, window - 1] when given (the windows must overlap).
  int hop = 0;
};

/// One encoded window.
struct WindowCode {
  int start = 0;              ///< first frame, in model frames of the encoded sequence
  int length = 0;             ///< frames covered: the window, or fewer for a short clip
  GroundTransform transform;  ///< canonical frame of the window (at frame `start`)
  Eigen::VectorXf z_l;        ///< [zl], the local encoder's mean
  Eigen::VectorXf z_g;        ///< [zg], the global encoder's mean
};

/// A motion as window latents.
struct EncodedMotion {
  Skeleton skeleton;            ///< the input's skeleton (decoded motions carry it)
  double fps = 30.0;            ///< the model's frame rate: the unit of WindowCode::start
  int frames = 0;               ///< model frames of the encoded sequence (N)
  std::vector<WindowCode> windows;
  /// The input's own frame rate and root path, for RootSource::kInput.
  double source_fps = 30.0;
  std::vector<Eigen::Vector3d> source_root_positions;

  /// Seconds from the first to the last model frame.
  double duration() const { return frames > 1 ? (frames - 1) / fps : 0.0; }
};

/// Normalised blend weights of `windows` (only start and length are read) at
/// model-frame position s: one weight per window, zero for windows that do not
/// cover s, summing to one. s is clamped to the covered range first.
std::vector<double> blend_weights(const std::vector<WindowCode>& windows, double s);

/// The networks the codec runs, one window at a time: the Eigen runtime's
/// behind the functions below that take a runtime::NemfRuntime; the
/// equivalence test implements it on libtorch. Matrices are row-major float,
/// one row per frame, rotations row-major 3x3 per joint (J joints of rig()).
class CodecPrior {
 public:
  using Rows = WindowMatrices::Rows;
  virtual ~CodecPrior() = default;
  virtual const NemfConfig& config() const = 0;
  virtual const RigInfo& rig() const = 0;
  /// The encoders' means z_l [zl] and z_g [zg] (resized) of a canonical
  /// window's local rotations [T, J * 9] (window_matrices()), every frame present.
  virtual void encode(const Rows& local_rotations, Eigen::VectorXf* z_l, Eigen::VectorXf* z_g) const = 0;
  /// The decoder for `window`'s latents at local frame positions [S]:
  /// rotations [S, J * 9] (resized).
  virtual void decode(const WindowCode& window, const Eigen::VectorXd& positions, Rows* rotations) const = 0;
  /// `window`'s root path [length, 3] (resized) at its model frames 0 ..
  /// length - 1 in its canonical frame: the dense decode, the GMP
  /// (GmpUse::Default) on it, forward Euler from the origin.
  virtual void root_path(const WindowCode& window, Rows* path) const = 0;
};

/// Encodes `motion` (>= 2 frames, any fps) with `model` (see the header comment).
EncodedMotion encode_motion(const runtime::NemfRuntime& model, const Motion& motion, const CodecOptions& options = {});
EncodedMotion encode_motion(const CodecPrior& prior, const Motion& motion, const CodecOptions& options = {});

enum class RootSource {
  kPrior,  ///< root translation from the global motion predictor, per window
  kInput,  ///< the input's root path, interpolated linearly
};

struct DecodeOptions {
  RootSource root = RootSource::kPrior;
};

/// Decodes at times i / fps, i = 0 .. frames - 1: a motion on code.skeleton at
/// `fps` with exactly `frames` frames. frames = 0 gives an empty motion.
Motion decode_motion(const runtime::NemfRuntime& model, const EncodedMotion& code, double fps, int frames,
                     const DecodeOptions& options = {});
Motion decode_motion(const CodecPrior& prior, const EncodedMotion& code, double fps, int frames,
                     const DecodeOptions& options = {});

/// Decodes at arbitrary `times` (seconds from the first frame, any order); the
/// result has one frame per time and carries `fps` as its frame rate label.
Motion decode_times(const runtime::NemfRuntime& model, const EncodedMotion& code, const std::vector<double>& times,
                    double fps, const DecodeOptions& options = {});
Motion decode_times(const CodecPrior& prior, const EncodedMotion& code, const std::vector<double>& times, double fps,
                    const DecodeOptions& options = {});

struct PriorResampleOptions {
  /// Add the input-minus-reconstruction residual (below). Without it the
  /// output is the plain decode.
  bool residual = true;
  RootSource root = RootSource::kPrior;
  CodecOptions codec;
};

/// Resampling with the prior: encode `motion`, decode at times i / fps
/// (i < frames). With the residual: at every input frame k the residual
/// between input and reconstruction is taken, per joint as the quaternion
/// r_k = q_input(k) * q_prior(k)^-1 and for the root as p_input(k) - p_prior(k);
/// it is interpolated to each output time (SLERP / LERP between the surrounding
/// input frames, held past the ends) and applied on the left of the decoded
/// rotation and added to the decoded root position. Output times whose input
/// frame position i * motion.fps / fps lies within 1e-5 (relative, as
/// resample_interpolate()) of an integer copy that input frame exactly, so known
/// frames come out as given. Throws mf::ModelMissingError (an InputError)
/// when ctx has no prior (plus the codec's errors).
Motion resample_with_prior(const Motion& motion, double fps, int frames, const TaskContext& ctx,
                           const PriorResampleOptions& options = {});
/// The same with the networks of `prior`.
Motion resample_with_prior(const CodecPrior& prior, const Motion& motion, double fps, int frames,
                           const PriorResampleOptions& options = {});

}  // namespace mf
