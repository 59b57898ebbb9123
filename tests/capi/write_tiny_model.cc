// Writes a tiny random model file (7-joint test skeleton, window 32) for the
// tests of the C API's clients (Python, the CLI), which cannot make one
// themselves; with --transformers also tiny random transformer in-betweeners
// next to it (motionfield-twostage.mfm, motionfield-citl.mfm in OUT's directory).
//   usage: mf_capi_tiny_model OUT.mfm [--transformers]
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <string>

#include "prior/inbetween/inbetweener.h"
#include "prior/model/model_file.h"
#include "prior/model/nemf.h"
#include "tests/test_util.h"

int main(int argc, char** argv) {
  const bool transformers = argc == 3 && std::strcmp(argv[2], "--transformers") == 0;
  if (argc != 2 && !transformers) {
    std::fprintf(stderr, "usage: mf_capi_tiny_model OUT.mfm [--transformers]\n");
    return 2;
  }
  try {
    const mf::NemfModel prior = mf::test::tiny_prior();
    mf::save_nemf(prior, argv[1]);
    if (transformers) {
      const std::filesystem::path dir = std::filesystem::path(argv[1]).parent_path();
      mf::save_inbetweener(*mf::test::tiny_transformer(mf::kTwoStageKind, prior.rig()),
                           (dir / "motionfield-twostage.mfm").string());
      mf::save_inbetweener(*mf::test::tiny_transformer(mf::kCitlKind, prior.rig()),
                           (dir / "motionfield-citl.mfm").string());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mf_capi_tiny_model: %s\n", e.what());
    return 1;
  }
  return 0;
}
