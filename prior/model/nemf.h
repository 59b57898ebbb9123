// The motion prior: a NeMF-style variational motion field.
//
//   local encoder  (skeleton-aware strided temporal convolutions over the
//                   local-motion features)                  -> mu, log sigma^2 of z_l
//   global encoder (strided temporal convolutions over the root orientation)
//                                                           -> mu, log sigma^2 of z_g
//   decoder f(t; z_l, z_g): an MLP on a positional encoding of continuous time
//                   t plus the latents, re-injected at every layer (z_g in the
//                   last `zg_layers`)   -> local 6D rotations of joints 1..J-1
//                                          and the root orientation (6D)
//   global motion predictor (GMP): temporal convolutions over the decoded
//                   heading-relative pose -> root velocity (heading frame),
//                   root height, foot contact logits; translation by integration.
//
// Time: a window holds `window` frames at `fps`; frame index s (any real number
// in [0, window - 1]) is encoded as t = s / window * 2 - 1 with sin/cos at
// frequencies 1, 2, 4, ..., 2^(pe_frequencies - 1). Decoding at another frame
// rate is asking for fractional frame indices.
//
// Short clips: windows shorter than `window` are placed at the start of the
// window; the encoder sees zeros and a 0 in its mask channel for the missing
// frames, and the decoder is simply not asked for them. Training uses the same
// masking, so clips of any length from 2 frames up are used.
//
// The torch modules are private to nemf.cc (pimpl) so that including this
// header does not pull in libtorch's module headers.
#pragma once

#include <ATen/core/Tensor.h>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "prior/model/nemf_config.h"
#include "prior/model/representation.h"

namespace mf {

/// Normalisation statistics (z-scores), measured on the training split.
struct NemfStats {
  at::Tensor feature_mean, feature_std;  ///< [J * 15] local-motion features
  at::Tensor root_mean, root_std;        ///< [6] root orientation 6D
  at::Tensor gmp_in_mean, gmp_in_std;    ///< [J * 3 + 6] GMP inputs
  at::Tensor gmp_out_mean, gmp_out_std;  ///< [4] root velocity (3) and height (1)
};

struct NemfLatent {
  at::Tensor mu_l, logvar_l;  ///< [B, zl]
  at::Tensor mu_g, logvar_g;  ///< [B, zg]
};

struct GmpOutput {
  at::Tensor velocity;        ///< [B, T, 3] root velocity in the heading frame, m/s
  at::Tensor height;          ///< [B, T, 1] root height, m
  at::Tensor contact_logits;  ///< [B, T, F]
};

/// With frozen weights, one window of at least this many frames is decoded
/// (and run through the GMP) in two halves on two threads when the calling
/// thread has two or more; shorter windows gain nothing from a second thread.
inline constexpr int kNemfParallelFrames = 64;

class NemfModel {
 public:
  NemfModel(const NemfConfig& config, const RigInfo& rig);
  ~NemfModel();
  NemfModel(NemfModel&&) noexcept;
  NemfModel& operator=(NemfModel&&) noexcept;

  const NemfConfig& config() const;
  const RigInfo& rig() const;
  NemfStats& stats();
  const NemfStats& stats() const;

  /// Encodes canonical windows: local_rotations [B, T, J, 3, 3] with
  /// 2 <= T <= window and mask [B, T] (1 = frame present). Frames beyond T
  /// count as missing.
  NemfLatent encode(const at::Tensor& local_rotations, const at::Tensor& mask) const;

  /// The same from precomputed inputs: raw (not normalised) features
  /// [B, T, J * 15] and root 6D [B, T, 6] as local_features() returns them.
  NemfLatent encode_features(const at::Tensor& features, const at::Tensor& root6d, const at::Tensor& mask) const;

  /// Decodes at frame indices `frames` ([S] shared by the batch, or [B, S]):
  /// local rotations [B, S, J, 3, 3], joint 0 being the root orientation in
  /// the canonical frame. z_l [B, zl], z_g [B, zg].
  at::Tensor decode(const at::Tensor& frames, const at::Tensor& z_l, const at::Tensor& z_g) const;

  /// The decoder's own output, before decode() turns it into rotation
  /// matrices: [B, S, J, 6], per joint the 6D of its rotation (the two first
  /// columns, not yet orthonormalised). For the Eigen runtime's equivalence
  /// tests (prior/runtime/), which compare it unnormalised.
  at::Tensor decode_sixd(const at::Tensor& frames, const at::Tensor& z_l, const at::Tensor& z_g) const;

  /// The GMP on a dense sequence of frames at the model's fps, [B, T, J, 3, 3] -> outputs.
  GmpOutput predict_global(const at::Tensor& local_rotations, GmpUse use = GmpUse::Default) const;

  /// The GMP from precomputed raw inputs [B, T, J * 3 + 6] (gmp_inputs()).
  GmpOutput predict_global_from_inputs(const at::Tensor& inputs, GmpUse use = GmpUse::Default) const;

  /// Whether GmpUse::Steering has a GMP of its own.
  bool has_steering_gmp() const;

  /// Root positions [B, T, 3] in the canonical frame from the GMP's outputs,
  /// starting at the origin (or start_xz [B, 2]).
  at::Tensor root_positions(const at::Tensor& local_rotations, const GmpOutput& gmp,
                            const at::Tensor& start_xz = {}) const;

  /// Every parameter, by stable name ("local_encoder.conv0.weight", ...).
  std::vector<std::pair<std::string, at::Tensor>> named_parameters() const;
  std::vector<at::Tensor> parameters() const;
  /// Parameters of the VAE (encoders and decoder) and of the default GMP, for
  /// separate optimisers (the steering GMP is in neither).
  std::vector<at::Tensor> vae_parameters() const;
  std::vector<at::Tensor> gmp_parameters() const;
  int64_t num_parameters() const;
  /// Training mode (affects nothing stochastic today; kept for symmetry).
  void train(bool on);
  /// Freezes (false) or unfreezes every parameter for autograd. Freezing also
  /// applies the skeleton convolutions' masks to their weights once, in place
  /// (outputs unchanged), so that inference skips them; weights edited in place
  /// afterwards are masked per call again.
  void set_requires_grad(bool on);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Positional encoding of frame indices [...] -> [..., 2 * frequencies].
at::Tensor time_encoding(const at::Tensor& frames, int window, int frequencies);

}  // namespace mf
