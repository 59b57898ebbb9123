// The NeMF prior on Eigen, without libtorch: the networks of prior/model/nemf.h
// loaded from the same model file (prior/model/model_container.h), for one
// window at a time, with the gradients the latent solvers need written out
// (the decoder's with respect to the latent codes, the GMP's with respect to
// its inputs). tests/runtime_equivalence_test.cc holds it to the libtorch
// implementation (outputs within 1e-5, gradients within 1e-4, relative to
// the largest value).
//
// Shapes: row-major float matrices with one row per frame (MatrixRXf);
// J joints, F feet of the model's rig (rig()). Units as in nemf.h: frame
// indices at the model's fps, metres, metres per second, 6D rotations.
// A loaded NemfRuntime is immutable and may be shared between threads; each
// thread evaluates with workspaces of its own.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "prior/model/nemf_config.h"
#include "prior/model/rig_info.h"
#include "prior/runtime/decoder.h"
#include "prior/runtime/encoders.h"
#include "prior/runtime/gmp.h"
#include "prior/runtime/kinematics.h"
#include "prior/runtime/tensor_ops.h"
#include "prior/util/binary_io.h"

namespace mf::runtime {

/// The latent Gaussians of one window, as NemfLatent in nemf.h.
struct LatentGaussians {
  Eigen::VectorXf mu_l, logvar_l;  ///< [zl]
  Eigen::VectorXf mu_g, logvar_g;  ///< [zg]
};

/// Normalisation statistics (NemfStats in nemf.h) as row vectors.
struct NemfRuntimeStats {
  RowVectorXf feature_mean, feature_std;  ///< [J * 15]
  RowVectorXf root_mean, root_std;        ///< [6]
  RowVectorXf gmp_in_mean, gmp_in_std;    ///< [J * 3 + 6]
  RowVectorXf gmp_out_mean, gmp_out_std;  ///< [4]
};

class NemfRuntime {
 public:
  /// The prior of a model file's bytes (format checks and errors as
  /// deserialize_nemf: InputError naming `source`).
  static NemfRuntime from_bytes(const uint8_t* data, size_t size, const std::string& source);
  /// The same from a whole file's bytes, each weight's pages given back to the
  /// system once copied (FileBytes::release): the load's peak memory is about
  /// the runtime's weights, not twice them.
  static NemfRuntime from_file(const FileBytes& file, const std::string& source);
  /// The prior of the model file at `path`.
  static NemfRuntime load(const std::string& path);

  const NemfConfig& config() const { return config_; }
  const RigInfo& rig() const { return rig_; }
  const NemfRuntimeStats& stats() const { return stats_; }
  const NemfDecoder& decoder() const { return *decoder_; }

  /// The decoder at frame indices `frames` [S] for z_l [zl], z_g [zg]:
  /// `out` [S, J * 6], per joint its rotation's 6D (NemfDecoder::decode).
  void decode(const Eigen::Ref<const Eigen::VectorXd>& frames, const Eigen::Ref<const Eigen::VectorXf>& z_l,
              const Eigen::Ref<const Eigen::VectorXf>& z_g, DecoderWorkspace* ws, MatrixRXf* out) const;
  /// d energy / d z_l and z_g from d energy / d out [S, J * 6] of the last decode in `ws`.
  void decode_vjp(DecoderWorkspace* ws, ConstMatrixRef g_out, Eigen::VectorXf* g_zl, Eigen::VectorXf* g_zg) const;

  /// Whether GmpUse::Steering has a GMP of its own.
  bool has_steering_gmp() const { return steering_gmp_ != nullptr; }
  /// The GMP on one dense window of raw inputs [T, J * 3 + 6] (gmp_inputs()
  /// in representation.h; normalised here): `out` [T, 4 + F] (resized), per
  /// frame the root velocity in the heading frame (3, m/s), the root height
  /// (1, m) and the feet's contact logits (F), as GmpOutput's fields.
  void predict_global(ConstMatrixRef inputs, GmpUse use, GmpWorkspace* ws, MatrixRXf* out) const;
  /// d energy / d inputs [T, J * 3 + 6] (resized) from d energy / d out
  /// [T, 4 + F] of the last predict_global in `ws` with the same `use`.
  void predict_global_vjp(GmpWorkspace* ws, GmpUse use, ConstMatrixRef g_out, MatrixRXf* g_inputs) const;

  /// The encoders on one window of raw features [T, J * 15] and root 6D
  /// [T, 6] (local_features() in representation.h) with mask [T] (1 = frame
  /// present), 1 <= T <= window; frames beyond T count as missing.
  LatentGaussians encode_features(ConstMatrixRef features, ConstMatrixRef root6d,
                                  const Eigen::Ref<const Eigen::VectorXf>& mask) const;
  /// The encoders on one canonical window of local rotations [T, J * 9]
  /// (window_matrices() of prior/model/canonical_window.h), every frame
  /// present, 1 <= T <= window: its local_features() at the model's frame
  /// rate, then encode_features(). Throws InputError on a bad shape.
  LatentGaussians encode_rotations(ConstMatrixRef local_rotations) const;

 private:
  NemfRuntime() = default;
  static NemfRuntime read(const uint8_t* data, size_t size, const std::string& source, const FileBytes* file);
  const NemfGmpNetwork& gmp(GmpUse use) const;
  NemfConfig config_;
  RigInfo rig_;
  NemfRuntimeStats stats_;
  std::shared_ptr<const NemfDecoder> decoder_;
  std::shared_ptr<const NemfEncoders> encoders_;
  std::shared_ptr<const NemfGmpNetwork> gmp_, steering_gmp_;
  std::shared_ptr<const Kinematics> kinematics_;
};

}  // namespace mf::runtime
