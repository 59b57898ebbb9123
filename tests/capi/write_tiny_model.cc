// Writes a tiny random model file (7-joint test skeleton, window 32) for the
// tests of the C API's clients (Python), which cannot make one themselves.
//   usage: mf_capi_tiny_model OUT.mfm
#include <ATen/ATen.h>

#include <cstdio>
#include <exception>

#include "prior/model/model_file.h"
#include "prior/model/nemf.h"
#include "prior/model/representation.h"
#include "tests/test_util.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: mf_capi_tiny_model OUT.mfm\n");
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
    mf::save_nemf(mf::NemfModel(c, mf::measure_rig(s, {&m})), argv[1]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mf_capi_tiny_model: %s\n", e.what());
    return 1;
  }
  return 0;
}
