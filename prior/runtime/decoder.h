// The NeMF decoder f(t; z_l, z_g) on Eigen, with its vector-Jacobian product
// with respect to the latent codes written out (prior/model/nemf.h describes
// the network; FrozenDecoderFunction in nemf.cc is the libtorch node this
// reproduces). One window per evaluation: the latents' contribution to every
// layer (W_zl z_l + W_zg z_g + the time features' bias) is the same for every
// frame, so it is computed once per evaluation; each frame then costs the
// per-row matrix products of the time features, the hidden layers and the head.
#pragma once

#include <cstdint>
#include <vector>

#include "prior/model/nemf_config.h"
#include "prior/runtime/tensor_ops.h"
#include "prior/runtime/weight_reader.h"

namespace mf::runtime {

/// What a decoder evaluation keeps for its VJP, and the VJP's scratch: a
/// caller that reuses one workspace across evaluations of the same number of
/// frames allocates nothing after the first. One workspace per thread.
struct DecoderWorkspace {
  MatrixRXf pe;                              ///< [S, 2 * pe_frequencies] time features
  std::vector<MatrixRXf> time_part;          ///< per layer [S, W]: pe times the layer's time weights
  Eigen::VectorXd time_frames;               ///< the frames pe and time_part are of
  uint64_t time_decoder = 0;                 ///< the decoder they are of (NemfDecoder's id; 0: none)
  std::vector<MatrixRXf> pre;                ///< per layer [S, W]: before the layer norm
  std::vector<MatrixRXf> hidden;             ///< per layer [S, W]: after the ReLU
  std::vector<Eigen::VectorXf> mean, rstd;   ///< per layer [S]: the layer norm's statistics
  std::vector<Eigen::VectorXf> latent_part;  ///< per layer [W]: what the latents add to every row
  MatrixRXf g, g_pre;                        ///< VJP scratch [S, W]
  Eigen::VectorXf columns;                   ///< VJP scratch [W]
};

/// The positional encoding of frame indices (any real value; a window holds
/// frames 0 .. window - 1), as time_encoding() in nemf.h: t = s / window * 2 - 1
/// in float32, then sin(2^i t) for i < frequencies, then cos(2^i t).
/// `pe` is resized to [S, 2 * frequencies].
void decoder_time_features(const Eigen::Ref<const Eigen::VectorXd>& frames, int window, int frequencies,
                           MatrixRXf* pe);

class NemfDecoder {
 public:
  /// Takes the decoder's weights ("decoder.*") for `config` and `joints`.
  NemfDecoder(const NemfConfig& config, int joints, WeightReader& weights);

  /// Decodes one window at frame indices `frames` [S] (fractional frames
  /// allowed) for z_l [zl] and z_g [zg]: `out` [S, J * 6] (resized), per
  /// joint the two first columns of its rotation matrix, 6D as in
  /// rotations_torch.h (joint 0: the root's orientation in the canonical
  /// frame). The workspace keeps what decode_vjp needs.
  void decode(const Eigen::Ref<const Eigen::VectorXd>& frames, const Eigen::Ref<const Eigen::VectorXf>& z_l,
              const Eigen::Ref<const Eigen::VectorXf>& z_g, DecoderWorkspace* ws, MatrixRXf* out) const;

  /// The gradient of an energy with respect to the latents, from its gradient
  /// g_out [S, J * 6] with respect to the last decode()'s output in `ws`:
  /// g_zl [zl], g_zg [zg] (resized, overwritten).
  void decode_vjp(DecoderWorkspace* ws, ConstMatrixRef g_out, Eigen::VectorXf* g_zl, Eigen::VectorXf* g_zg) const;

  /// Floating-point operations of the matrix products of one evaluation of
  /// S frames: the forward's (latent part included; not the time features'
  /// products, made once while the frames stay the same) or the VJP's.
  int64_t forward_flops(int64_t S) const;
  int64_t vjp_flops(int64_t S) const;

  const NemfConfig& config() const { return config_; }
  int joints() const { return joints_; }

 private:
  struct Layer {
    WeightMatrix pe;     // [W, 2F]
    RowVectorXf pe_bias; // [W]
    MatrixRXf zl;        // [W, zl]
    WeightMatrix hidden; // [W, W]; empty in layer 0
    MatrixRXf zg;        // [W, zg]; empty before the last zg_layers
    RowVectorXf norm_weight, norm_bias;
  };
  void add_latent_parts(const Eigen::Ref<const Eigen::VectorXf>& z_l, const Eigen::Ref<const Eigen::VectorXf>& z_g,
                        DecoderWorkspace* ws) const;
  // The time features and their products with each layer's time weights, kept
  // in the workspace while the frames are the same (a solve's evaluations).
  void time_parts(const Eigen::Ref<const Eigen::VectorXd>& frames, DecoderWorkspace* ws) const;
  NemfConfig config_;
  int joints_;
  std::vector<Layer> layers_;
  WeightMatrix head_;         // [J * 6, W]
  RowVectorXf head_bias_;     // [J * 6], the identity rotation's 6D added
  uint64_t id_;               // the workspaces' key for time_parts
};

}  // namespace mf::runtime
