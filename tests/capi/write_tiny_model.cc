// Writes a tiny random model file (7-joint test skeleton, window 32) for the
// tests of the C API's clients (Python, the CLI), which cannot make one
// themselves; with --transformers also tiny random transformer in-betweeners
// next to it (motionfield-twostage.mfm, motionfield-citl.mfm in OUT's directory).
//   usage: mf_capi_tiny_model OUT.mfm [--transformers]
#include <ATen/ATen.h>

#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <map>
#include <string>

#include "prior/inbetween/inbetweener.h"
#include "prior/model/model_file.h"
#include "prior/model/nemf.h"
#include "prior/model/representation.h"
#include "tests/test_util.h"

int main(int argc, char** argv) {
  const bool transformers = argc == 3 && std::strcmp(argv[2], "--transformers") == 0;
  if (argc != 2 && !transformers) {
    std::fprintf(stderr, "usage: mf_capi_tiny_model OUT.mfm [--transformers]\n");
    return 2;
  }
  try {
    at::manual_seed(0);
    mf::NemfConfig c;
    c.window = 32;
    c.decoder_width = 32;
    c.decoder_layers = 3;
    c.zl = 8;
    c.zg = 4;
    c.zg_layers = 2;
    c.encoder_channels = 4;
    c.gmp_width = 8;
    c.gmp_blocks = 1;
    const mf::Skeleton s = mf::test::small_skeleton();
    const mf::Motion m = mf::test::random_motion(s, 60, 30.0, 3);
    const mf::RigInfo rig = mf::measure_rig(s, {&m});
    mf::save_nemf(mf::NemfModel(c, rig), argv[1]);
    if (transformers) {
      const std::filesystem::path dir = std::filesystem::path(argv[1]).parent_path();
      std::map<std::string, double> hp = {{"width", 16}, {"layers", 1}, {"heads", 2}, {"ffn", 32}, {"window", 32}};
      mf::save_inbetweener(*mf::make_inbetweener(mf::kTwoStageKind, hp, rig), (dir / "motionfield-twostage.mfm").string());
      hp["time_dim"] = 4;
      mf::save_inbetweener(*mf::make_inbetweener(mf::kCitlKind, hp, rig), (dir / "motionfield-citl.mfm").string());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mf_capi_tiny_model: %s\n", e.what());
    return 1;
  }
  return 0;
}
