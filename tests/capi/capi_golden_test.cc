// Golden tests of the shipped models (models/): the default methods on the
// bundled clip, through the C API, at one intra-op thread give exactly the
// stored output (a digest of its floats, tests/golden/shipped_models.txt); at
// two threads they stay within a stated tolerance of the one-thread output.
// After a deliberate change (a retrained model, a changed method) regenerate
// the digests with scripts/update-golden.sh (see tests/golden/README.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "prior/util/binary_io.h"
#include "tests/capi/capi_test_util.h"

namespace mf::capi_test {
namespace {

const std::string kGoldenFile = "tests/golden/shipped_models.txt";
const std::string kUpdateCommand = "scripts/update-golden.sh";

enum class Task { Inbetween, Fill, Resample };

struct GoldenCase {
  std::string name;
  Task task;
  const char* method;  // nullptr: the default method (mf_default_method)
  // Everything the output depends on besides the code, relative to the source tree.
  std::vector<std::string> files;
};

const std::string kSample = "samples/walk_keyframes.bvh";
const std::string kRig = "models/motionfield-rig.json";
const std::string kPrior = "models/motionfield-prior.mfm";
const std::string kTwoStage = "models/motionfield-twostage.mfm";
const std::string kCitl = "models/motionfield-citl.mfm";

const std::vector<GoldenCase>& golden_cases() {
  static const std::vector<GoldenCase> cases = {
      {"inbetween_default", Task::Inbetween, nullptr, {kSample, kPrior, kTwoStage, kRig}},
      {"inbetween_detail", Task::Inbetween, "detail", {kSample, kTwoStage, kRig}},
      {"inbetween_citl", Task::Inbetween, "citl", {kSample, kCitl, kRig}},
      {"resample_default", Task::Resample, nullptr, {kSample, kPrior, kRig}},
      {"fill_default", Task::Fill, nullptr, {kSample, kPrior, kTwoStage, kRig}},
  };
  return cases;
}

std::string source_path(const std::string& relative) { return std::string(MF_SOURCE_DIR) + "/" + relative; }

std::string hex64(uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

// "path=size:fnv1a64" of each file the case depends on, comma-separated.
std::string fingerprint(const GoldenCase& c) {
  std::string out;
  for (const std::string& f : c.files) {
    const std::vector<uint8_t> bytes = read_file_bytes(source_path(f));
    if (!out.empty()) out += ",";
    out += f + "=" + std::to_string(bytes.size()) + ":" + hex64(fnv1a64_bytes(bytes.data(), bytes.size()));
  }
  return out;
}

struct Output {
  std::vector<float> rotations, root_positions;
  // FNV-1a 64 over the frame count and the bytes of every float.
  std::string digest() const {
    const int32_t frames = static_cast<int32_t>(root_positions.size() / 3);
    uint64_t h = fnv1a64_bytes(reinterpret_cast<const uint8_t*>(&frames), sizeof frames);
    h = fnv1a64_bytes(reinterpret_cast<const uint8_t*>(rotations.data()), rotations.size() * sizeof(float), h);
    return hex64(fnv1a64_bytes(reinterpret_cast<const uint8_t*>(root_positions.data()),
                               root_positions.size() * sizeof(float), h));
  }
};

const mf_model* shipped_model() {
  static const ModelPtr model = [] {
    mf_model* m = nullptr;
    const int status = mf_model_load(source_path(kPrior).c_str(), &m);
    EXPECT_EQ(status, MF_OK) << describe(status);
    return ModelPtr(m);
  }();
  return model.get();
}

Output run(const GoldenCase& c, int threads) {
  EXPECT_EQ(mf_set_num_threads(threads), MF_OK);
  int32_t now = 0;
  EXPECT_EQ(mf_get_num_threads(&now), MF_OK);
  EXPECT_EQ(now, threads);
  mf_motion* input = nullptr;
  int status = mf_motion_load_bvh(source_path(kSample).c_str(), nullptr, &input);
  EXPECT_EQ(status, MF_OK) << describe(status);
  const MotionPtr in(input);
  mf_task_options options;
  mf_task_options_init(&options);
  options.method = c.method;
  options.seed = 1;
  mf_motion* raw = nullptr;
  if (c.task == Task::Inbetween) {
    const int32_t keys[] = {0, 20, 40, 60};
    status = mf_inbetween(shipped_model(), input, keys, 4, &options, &raw);
  } else if (c.task == Task::Fill) {
    status = mf_fill(shipped_model(), input, 15, 45, &options, &raw);
  } else {
    status = mf_resample(shipped_model(), input, 60.0, &options, &raw);
  }
  EXPECT_EQ(status, MF_OK) << c.name << ": " << describe(status);
  const MotionPtr out(raw);
  if (status != MF_OK) return {};
  return {rotations(raw), root_positions(raw)};
}

struct Stored {
  std::string fingerprint, digest;
};

std::map<std::string, Stored> read_golden() {
  std::map<std::string, Stored> out;
  std::ifstream in(source_path(kGoldenFile));
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string name;
    Stored s;
    fields >> name >> s.fingerprint >> s.digest;
    out[name] = s;
  }
  return out;
}

void write_golden(const std::map<std::string, Stored>& entries) {
  std::ofstream out(source_path(kGoldenFile));
  out << "# Golden outputs of the shipped models (tests/capi/capi_golden_test.cc): one line per case,\n"
         "#   name  file=size:fnv1a64,...  output-fnv1a64\n"
         "# the files each output depends on (models, input) and the digest of the output's floats\n"
         "# at one intra-op thread. Regenerate after a deliberate change with\n"
         "#   "
      << kUpdateCommand << " [BUILD_DIR]\n";
  for (const GoldenCase& c : golden_cases()) {
    const auto it = entries.find(c.name);
    if (it != entries.end()) out << c.name << " " << it->second.fingerprint << " " << it->second.digest << "\n";
  }
  EXPECT_TRUE(out.flush().good()) << "cannot write " << kGoldenFile;
}

bool updating() {
  const char* v = std::getenv("MF_UPDATE_GOLDEN");
  return v != nullptr && std::string(v) == "1";
}

// One process for all cases (each ctest case is a process of its own, and
// loading the shipped models costs more than most cases).
TEST(CApiGolden, OneThreadMatchesTheStoredDigests) {
  ASSERT_NE(shipped_model(), nullptr);
  std::map<std::string, Stored> entries = read_golden();
  for (const GoldenCase& c : golden_cases()) {
    SCOPED_TRACE(c.name);
    const std::string now = fingerprint(c);
    const Output out = run(c, 1);
    ASSERT_FALSE(out.rotations.empty());
    if (updating()) {
      entries[c.name] = {now, out.digest()};
      continue;
    }
    const auto it = entries.find(c.name);
    ASSERT_NE(it, entries.end()) << "no stored digest of " << c.name << " in " << kGoldenFile << "; run "
                                 << kUpdateCommand;
    EXPECT_EQ(it->second.fingerprint, now)
        << "a file " << c.name << " depends on changed since the digests were stored (see the sizes and checksums "
        << "above); check the outputs and run " << kUpdateCommand;
    EXPECT_EQ(it->second.digest, out.digest())
        << "the output of " << c.name << " changed; if that is intended, run " << kUpdateCommand;
  }
  if (updating()) write_golden(entries);
}

// Rotations are unit quaternions and root positions metres: 1e-3 is well below
// a visible difference, far above the last-bit differences of reordered sums.
constexpr float kTwoThreadTolerance = 1e-3f;

float max_difference(const std::vector<float>& a, const std::vector<float>& b) {
  EXPECT_EQ(a.size(), b.size());
  float d = 0.0f;
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

TEST(CApiGolden, TwoThreadsStayCloseToOneThread) {
  ASSERT_NE(shipped_model(), nullptr);
  for (const GoldenCase& c : golden_cases()) {
    SCOPED_TRACE(c.name);
    const Output one = run(c, 1), two = run(c, 2);
    ASSERT_FALSE(one.rotations.empty());
    const float rotation = max_difference(one.rotations, two.rotations);
    const float root = max_difference(one.root_positions, two.root_positions);
    RecordProperty("max_rotation_difference_" + c.name, ::testing::PrintToString(rotation));
    RecordProperty("max_root_difference_" + c.name, ::testing::PrintToString(root));
    EXPECT_LE(rotation, kTwoThreadTolerance);
    EXPECT_LE(root, kTwoThreadTolerance);
  }
}

}  // namespace
}  // namespace mf::capi_test
