#include "tests/capi/capi_test_util.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "prior/model/model_file.h"
#include "tests/test_util.h"

namespace mf::capi_test {
namespace {

// The model file, in a directory of this process removed at exit (ctest runs
// every test in its own process, several at once).
struct TinyModelFile {
  std::string dir, path;
  std::vector<uint8_t> bytes;
  TinyModelFile() {
    const NemfModel model = test::tiny_prior();
    dir = test::scratch_dir("capi-" + std::to_string(::getpid()));
    path = dir + "/tiny.mfm";
    save_nemf(model, path);
    bytes = serialize_nemf(model);
  }
  ~TinyModelFile() {
    std::error_code ignored;
    std::filesystem::remove_all(dir, ignored);
  }
};

const TinyModelFile& tiny() {
  static const TinyModelFile file;
  return file;
}

}  // namespace

std::string describe(int status) { return std::string(mf_status_name(status)) + ": " + mf_last_error_message(); }

std::string sample_bvh() { return std::string(MF_SOURCE_DIR) + "/samples/walk_keyframes.bvh"; }

const std::string& tiny_model_path() { return tiny().path; }
const std::vector<uint8_t>& tiny_model_bytes() { return tiny().bytes; }

ModelPtr load_tiny_model() {
  mf_model* m = nullptr;
  const int status = mf_model_load(tiny_model_path().c_str(), &m);
  EXPECT_EQ(status, MF_OK) << describe(status);
  return ModelPtr(m);
}

MotionPtr to_capi(const Motion& m) {
  std::vector<const char*> names;
  for (const std::string& n : m.skeleton.names) names.push_back(n.c_str());
  std::vector<int32_t> parents(m.skeleton.parents.begin(), m.skeleton.parents.end());
  std::vector<float> offsets, rot, root;
  for (const auto& o : m.skeleton.offsets)
    for (int k = 0; k < 3; ++k) offsets.push_back(static_cast<float>(o[k]));
  for (const auto& q : m.rotations) {
    rot.push_back(static_cast<float>(q.w()));
    rot.push_back(static_cast<float>(q.x()));
    rot.push_back(static_cast<float>(q.y()));
    rot.push_back(static_cast<float>(q.z()));
  }
  for (const auto& p : m.root_positions)
    for (int k = 0; k < 3; ++k) root.push_back(static_cast<float>(p[k]));
  mf_motion* out = nullptr;
  const int status = mf_motion_create(m.num_joints(), names.data(), parents.data(), offsets.data(), m.num_frames(),
                                      m.fps, rot.data(), root.data(), &out);
  EXPECT_EQ(status, MF_OK) << describe(status);
  return MotionPtr(out);
}

MotionPtr random_capi_motion(int frames, double fps, uint32_t seed) {
  return to_capi(test::random_motion(test::small_skeleton(), frames, fps, seed));
}

std::vector<float> rotations(const mf_motion* m) {
  size_t n = 0;
  EXPECT_EQ(mf_motion_get_rotations(m, nullptr, 0, &n), MF_OK);
  std::vector<float> out(n);
  EXPECT_EQ(mf_motion_get_rotations(m, out.data(), out.size(), &n), MF_OK);
  return out;
}

std::vector<float> root_positions(const mf_motion* m) {
  size_t n = 0;
  EXPECT_EQ(mf_motion_get_root_positions(m, nullptr, 0, &n), MF_OK);
  std::vector<float> out(n);
  EXPECT_EQ(mf_motion_get_root_positions(m, out.data(), out.size(), &n), MF_OK);
  return out;
}

std::vector<float> global_positions(const mf_motion* m) {
  size_t n = 0;
  EXPECT_EQ(mf_motion_get_global_positions(m, nullptr, 0, &n), MF_OK);
  std::vector<float> out(n);
  EXPECT_EQ(mf_motion_get_global_positions(m, out.data(), out.size(), &n), MF_OK);
  return out;
}

int frame_count(const mf_motion* m) {
  int32_t n = -1;
  EXPECT_EQ(mf_motion_get_frame_count(m, &n), MF_OK);
  return n;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> methods_with(uint32_t flags) {
  int32_t count = 0;
  EXPECT_EQ(mf_method_count(&count), MF_OK);
  std::vector<std::string> out;
  for (int32_t i = 0; i < count; ++i) {
    const char* name = nullptr;
    uint32_t f = 0;
    EXPECT_EQ(mf_method_get(i, &name, nullptr, &f), MF_OK);
    if ((f & flags) == flags) out.push_back(name);
  }
  return out;
}

}  // namespace mf::capi_test
