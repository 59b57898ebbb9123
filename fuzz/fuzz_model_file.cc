// Fuzz target: the model-file loaders, the prior's (deserialize_nemf,
// prior/model/model_file.h; and the Eigen runtime's, NemfRuntime::from_bytes,
// prior/runtime/nemf_runtime.h) and every in-betweener kind's
// (deserialize_inbetweener, prior/inbetween/inbetweener.h), on any bytes.
// Contract checked: a bad file throws mf::InputError (any other exception, a
// crash, a sanitizer report or an allocation beyond libFuzzer's -rss_limit_mb /
// -malloc_limit_mb is a finding).
//
// The file ends with an FNV-1a checksum of its payload; a random mutation
// would almost always fail it and never reach the parser behind it. So when
// the header announces a payload that fits, the target rewrites the checksum
// to match (the mismatch itself is covered by tests/prior_model_test.cc).
// The seeds are tiny model files of each kind (fuzz/make_model_seeds.cc).
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "prior/inbetween/inbetweener.h"
#include "prior/model/model_file.h"
#include "prior/motion/errors.h"
#include "prior/runtime/nemf_runtime.h"
#include "prior/util/binary_io.h"
#include "prior/util/threads.h"

namespace {

// Rewrites the checksum after the payload when the header is consistent.
void fix_checksum(std::vector<uint8_t>& b) {
  size_t pos = 8 + 4;  // magic, version
  uint32_t kind_len;
  if (b.size() < pos + 4) return;
  std::memcpy(&kind_len, b.data() + pos, 4);
  pos += 4;
  if (kind_len > b.size() - pos) return;
  pos += kind_len;
  uint64_t payload;
  if (b.size() - pos < 8) return;
  std::memcpy(&payload, b.data() + pos, 8);
  pos += 8;
  if (payload > b.size() - pos || b.size() - pos - payload < 8) return;
  const uint64_t sum = mf::fnv1a64_bytes(b.data() + pos, payload);
  std::memcpy(b.data() + pos + payload, &sum, 8);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  mf::set_compute_threads(1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<uint8_t> bytes(data, data + size);
  fix_checksum(bytes);
  try {
    const mf::NemfModel model = mf::deserialize_nemf(bytes.data(), bytes.size(), "in.mfm");
  } catch (const mf::InputError&) {
  }
  try {
    const mf::runtime::NemfRuntime runtime = mf::runtime::NemfRuntime::from_bytes(bytes.data(), bytes.size(), "in.mfm");
  } catch (const mf::InputError&) {
  }
  try {
    const std::unique_ptr<mf::InbetweenModel> model =
        mf::deserialize_inbetweener(bytes.data(), bytes.size(), "in.mfm");
  } catch (const mf::InputError&) {
  }
  return 0;
}
