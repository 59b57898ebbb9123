#include "fuzz/tiny_models.h"

#include <ATen/ATen.h>

#include "tests/test_util.h"

namespace mf::fuzz {

NemfModel micro_prior() {
  NemfConfig c;
  c.window = 16;
  c.pe_frequencies = 1;
  c.decoder_width = 8;
  c.decoder_layers = 1;
  c.zl = 2;
  c.zg = 1;
  c.zg_layers = 1;
  c.encoder_channels = 1;
  c.gmp_width = 4;
  c.gmp_kernel = 1;
  c.gmp_blocks = 0;
  return test::tiny_prior(0, c, test::tiny_rig());
}

std::unique_ptr<InbetweenModel> micro_inbetweener(const std::string& kind, const RigInfo& rig) {
  at::manual_seed(0);
  std::map<std::string, double> hp = {{"width", 8}, {"layers", 1}, {"heads", 1}, {"ffn", 8}, {"window", 16}};
  if (kind == kCitlKind) hp["time_dim"] = 2;
  std::unique_ptr<InbetweenModel> model = make_inbetweener(kind, hp, rig);
  model->set_requires_grad(false);
  return model;
}

}  // namespace mf::fuzz
