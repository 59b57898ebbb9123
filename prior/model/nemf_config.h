// The NeMF prior's hyperparameters: a plain struct, torch-free, shared by the
// libtorch network (nemf.h), the model file (model_file.h, model_container.h)
// and the Eigen runtime (prior/runtime/). The network they describe is
// documented in nemf.h.
#pragma once

#include <map>
#include <string>

namespace mf {

/// The model file's kind string of the NeMF prior.
constexpr char kNemfKind[] = "nemf";

struct NemfConfig {
  int window = 128;          ///< frames per window
  double fps = 30.0;         ///< frame rate of the training data
  int pe_frequencies = 7;    ///< positional-encoding octaves (NeMF: 7)
  int decoder_width = 256;
  int decoder_layers = 6;
  int zl = 256;              ///< local latent size
  int zg = 64;               ///< global (root orientation) latent size
  int zg_layers = 3;         ///< the last layers that also take z_g
  int encoder_channels = 12; ///< per-joint channels of the first skeleton conv (then doubled once)
  int gmp_width = 128;
  int gmp_kernel = 7;
  int gmp_blocks = 3;
  /// 1: a second GMP of the same sizes, sharing the GMP statistics, for the
  /// tasks that steer the root along a path (GmpUse::Steering). A GMP reading
  /// the VAE's reconstructions in-betweens better; one trained on captured
  /// motion follows a path better. Files without it load with 0.
  int steering_gmp = 0;

  /// Empty when valid, else what is wrong.
  std::string validate() const;
  /// "decoder 6x256, z_l 256, z_g 64, ..." for logs and the model card.
  std::string describe() const;
  /// Named numeric fields, for the model file.
  std::map<std::string, double> to_map() const;
  static NemfConfig from_map(const std::map<std::string, double>& values);
};

/// The configuration of a model file's hyperparameters (from_map, then
/// validate), or InputError naming `source` and what is wrong.
NemfConfig checked_nemf_config(const std::map<std::string, double>& hyperparameters, const std::string& source);

/// Which GMP a task asks for: the default one, or the steering GMP where the
/// model has one (NemfConfig::steering_gmp; else the default).
enum class GmpUse { Default, Steering };

}  // namespace mf
