// Writes the seed corpus of the model-file fuzz target: the smallest model
// files of each kind the loaders accept (the prior, and every in-betweener
// kind of inbetweener_kinds()), on the 7-joint test rig, random weights.
//   usage: mf_fuzz_make_model_seeds OUT_DIR
// The files in fuzz/corpus/fuzz_model_file/ were made by this program.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "fuzz/tiny_models.h"
#include "prior/inbetween/inbetweener.h"
#include "prior/model/model_file.h"

namespace {

void write(const std::filesystem::path& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error(path.string() + ": cannot write");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: mf_fuzz_make_model_seeds OUT_DIR\n");
    return 2;
  }
  try {
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    const mf::NemfModel prior = mf::fuzz::micro_prior();
    write(dir / "seed-nemf.mfm", mf::serialize_nemf(prior));
    for (const mf::InbetweenerKind& kind : mf::inbetweener_kinds()) {
      write(dir / ("seed-" + kind.name + ".mfm"),
            mf::serialize_inbetweener(*mf::fuzz::micro_inbetweener(kind.name, prior.rig())));
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mf_fuzz_make_model_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
