#include "prior/model/nemf_config.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>

#include "prior/motion/errors.h"

namespace mf {

std::string NemfConfig::validate() const {
  std::ostringstream e;
  if (window < 16 || window % 16 != 0) e << "window must be a positive multiple of 16; ";
  if (!(fps > 0) || !std::isfinite(fps)) e << "fps must be positive; ";
  if (pe_frequencies < 1 || pe_frequencies > 16) e << "pe_frequencies must be in [1, 16]; ";
  if (decoder_width < 8 || decoder_width > 4096) e << "decoder_width must be in [8, 4096]; ";
  if (decoder_layers < 1 || decoder_layers > 32) e << "decoder_layers must be in [1, 32]; ";
  if (zl < 1 || zl > 4096 || zg < 1 || zg > 4096) e << "latent sizes must be in [1, 4096]; ";
  if (zg_layers < 1 || zg_layers > decoder_layers) e << "zg_layers must be in [1, decoder_layers]; ";
  if (encoder_channels < 1 || encoder_channels > 256) e << "encoder_channels must be in [1, 256]; ";
  // Upper bounds too: a model file's hyperparameters size the network built
  // before its weights are read (a fuzzed gmp_width of 2e9 asked for 200 GB).
  if (window > 4096) e << "window must be at most 4096; ";
  if (gmp_width < 4 || gmp_width > 4096 || gmp_kernel < 1 || gmp_kernel > 63 || gmp_kernel % 2 == 0 ||
      gmp_blocks < 0 || gmp_blocks > 64)
    e << "bad GMP sizes (width in [4, 4096], odd kernel in [1, 63], blocks in [0, 64]); ";
  if (steering_gmp != 0 && steering_gmp != 1) e << "steering_gmp must be 0 or 1; ";
  return e.str();
}

std::string NemfConfig::describe() const {
  std::ostringstream s;
  s << "decoder " << decoder_layers << "x" << decoder_width << ", z_l " << zl << ", z_g " << zg << " (last "
    << zg_layers << " layers), PE " << pe_frequencies << " octaves, encoder channels " << encoder_channels
    << ", GMP " << gmp_blocks << " blocks x " << gmp_width << " (kernel " << gmp_kernel << ")"
    << (steering_gmp ? " and a steering GMP of its sizes" : "") << ", window " << window << " frames at " << fps
    << " fps";
  return s.str();
}

std::map<std::string, double> NemfConfig::to_map() const {
  std::map<std::string, double> m{{"window", window},
                                  {"fps", fps},
                                  {"pe_frequencies", pe_frequencies},
                                  {"decoder_width", decoder_width},
                                  {"decoder_layers", decoder_layers},
                                  {"zl", zl},
                                  {"zg", zg},
                                  {"zg_layers", zg_layers},
                                  {"encoder_channels", encoder_channels},
                                  {"gmp_width", gmp_width},
                                  {"gmp_kernel", gmp_kernel},
                                  {"gmp_blocks", gmp_blocks}};
  // Written only when present, so that files without it stay as they were.
  if (steering_gmp) m["steering_gmp"] = steering_gmp;
  return m;
}

NemfConfig NemfConfig::from_map(const std::map<std::string, double>& v) {
  NemfConfig c;
  auto get = [&](const char* k, auto& field) {
    auto it = v.find(k);
    if (it == v.end()) throw InputError(std::string("model hyperparameter '") + k + "' is missing");
    using Field = std::remove_reference_t<decltype(field)>;
    if constexpr (std::is_integral_v<Field>) {
      // Casting a double outside int's range (or NaN) is undefined; validate()
      // checks the ranges of the values that fit.
      const double d = it->second;
      if (!(d == std::floor(d) && d >= std::numeric_limits<Field>::min() && d <= std::numeric_limits<Field>::max()))
        throw InputError(std::string("model hyperparameter '") + k + "' must be an integer");
    }
    field = static_cast<Field>(it->second);
  };
  get("window", c.window);
  get("fps", c.fps);
  get("pe_frequencies", c.pe_frequencies);
  get("decoder_width", c.decoder_width);
  get("decoder_layers", c.decoder_layers);
  get("zl", c.zl);
  get("zg", c.zg);
  get("zg_layers", c.zg_layers);
  get("encoder_channels", c.encoder_channels);
  get("gmp_width", c.gmp_width);
  get("gmp_kernel", c.gmp_kernel);
  get("gmp_blocks", c.gmp_blocks);
  if (v.count("steering_gmp")) get("steering_gmp", c.steering_gmp);
  return c;
}

NemfConfig checked_nemf_config(const std::map<std::string, double>& hyperparameters, const std::string& source) {
  NemfConfig config = NemfConfig::from_map(hyperparameters);
  const std::string problem = config.validate();
  if (!problem.empty()) throw InputError(source + ": invalid hyperparameters: " + problem);
  return config;
}

}  // namespace mf
