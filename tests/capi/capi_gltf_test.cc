// glTF output (mf_motion_save_gltf, mf_motion_save_gltf_to_memory) read back
// with tinygltf: the node hierarchy, rest offsets, frame times, every frame's
// local rotations and the root translation match the motion to 1e-5 (metres:
// the BVH's unit converted). The writer's refusals (non-finite numbers, no
// frames, numbers beyond 32-bit floats) are checked on mf::format_gltf, which
// the C API calls: a C caller cannot make such a motion.
#include <gtest/gtest.h>

#include <tiny_gltf.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "prior/motion/errors.h"
#include "prior/motion/motion_gltf.h"
#include "tests/capi/capi_test_util.h"
#include "tests/test_util.h"

namespace mf::capi_test {
namespace {

constexpr double kTol = 1e-5;

std::vector<uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

tinygltf::Model parse(const std::vector<uint8_t>& bytes, bool binary) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string error, warning;
  const bool ok = binary ? loader.LoadBinaryFromMemory(&model, &error, &warning, bytes.data(),
                                                       static_cast<unsigned>(bytes.size()))
                         : loader.LoadASCIIFromString(&model, &error, &warning,
                                                      reinterpret_cast<const char*>(bytes.data()),
                                                      static_cast<unsigned>(bytes.size()), "");
  EXPECT_TRUE(ok) << error;
  EXPECT_EQ(warning, "");
  return model;
}

// The floats of accessor `index` (tightly packed, as the writer makes them).
std::vector<float> floats(const tinygltf::Model& g, int index) {
  const tinygltf::Accessor& a = g.accessors.at(index);
  EXPECT_EQ(a.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT);
  const tinygltf::BufferView& v = g.bufferViews.at(a.bufferView);
  const size_t n = a.count * static_cast<size_t>(tinygltf::GetNumComponentsInType(a.type));
  EXPECT_LE(a.byteOffset + n * sizeof(float), v.byteLength);
  std::vector<float> out(n);
  std::memcpy(out.data(), g.buffers.at(v.buffer).data.data() + v.byteOffset + a.byteOffset, n * sizeof(float));
  return out;
}

std::string joint_name(const mf_motion* m, int32_t j) {
  size_t needed = 0;
  EXPECT_EQ(mf_motion_get_joint_name(m, j, nullptr, 0, &needed), MF_OK);
  std::string name(needed, '\0');
  EXPECT_EQ(mf_motion_get_joint_name(m, j, name.data(), name.size(), &needed), MF_OK);
  name.resize(needed - 1);
  return name;
}

template <class T, class Get>
std::vector<T> get_array(const mf_motion* m, Get get) {
  size_t needed = 0;
  EXPECT_EQ(get(m, nullptr, 0, &needed), MF_OK);
  std::vector<T> out(needed);
  EXPECT_EQ(get(m, out.data(), out.size(), &needed), MF_OK);
  return out;
}

// Nodes: one per joint, named after it, children = the joints whose parent it
// is, translation = the rest offset; the scene's root is joint 0.
void expect_skeleton(const tinygltf::Model& g, const mf_motion* m) {
  int32_t joints = 0;
  ASSERT_EQ(mf_motion_get_joint_count(m, &joints), MF_OK);
  const std::vector<int32_t> parents = get_array<int32_t>(m, mf_motion_get_parents);
  const std::vector<float> offsets = get_array<float>(m, mf_motion_get_offsets);
  ASSERT_EQ(g.nodes.size(), static_cast<size_t>(joints));
  ASSERT_EQ(g.scenes.size(), 1u);
  EXPECT_EQ(g.scenes[0].nodes, std::vector<int>{0});
  std::vector<int> parent_of(joints, -1);
  for (int j = 0; j < joints; ++j)
    for (int child : g.nodes[j].children) parent_of.at(child) = j;
  for (int j = 0; j < joints; ++j) {
    const tinygltf::Node& node = g.nodes[j];
    EXPECT_EQ(node.name, joint_name(m, j));
    EXPECT_EQ(parent_of[j], parents[j]) << node.name;
    ASSERT_EQ(node.translation.size(), 3u);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(node.translation[k], offsets[3 * j + k], kTol) << node.name;
    EXPECT_TRUE(node.rotation.empty() && node.scale.empty() && node.mesh < 0 && node.skin < 0);
  }
}

// The animation: input = the frame times; per joint a rotation channel
// (x, y, z, w) equal to the normalised local rotations; the root's translation.
void expect_animation(const tinygltf::Model& g, const mf_motion* m) {
  int32_t joints = 0, frames = 0;
  double fps = 0;
  ASSERT_EQ(mf_motion_get_joint_count(m, &joints), MF_OK);
  ASSERT_EQ(mf_motion_get_frame_count(m, &frames), MF_OK);
  ASSERT_EQ(mf_motion_get_fps(m, &fps), MF_OK);
  const std::vector<float> rotations = get_array<float>(m, mf_motion_get_rotations);
  const std::vector<float> root = get_array<float>(m, mf_motion_get_root_positions);
  ASSERT_EQ(g.animations.size(), 1u);
  const tinygltf::Animation& a = g.animations[0];
  ASSERT_EQ(a.channels.size(), static_cast<size_t>(joints) + 1);
  std::vector<int> rotation_channels(joints, 0);
  for (const tinygltf::AnimationChannel& c : a.channels) {
    const tinygltf::AnimationSampler& s = a.samplers.at(c.sampler);
    EXPECT_EQ(s.interpolation, "LINEAR");
    const std::vector<float> times = floats(g, s.input);
    ASSERT_EQ(times.size(), static_cast<size_t>(frames));
    for (int f = 0; f < frames; ++f) ASSERT_NEAR(times[f], f / fps, kTol);
    const std::vector<float> out = floats(g, s.output);
    const int j = c.target_node;
    if (c.target_path == "translation") {
      EXPECT_EQ(j, 0);
      ASSERT_EQ(out.size(), root.size());
      for (size_t i = 0; i < out.size(); ++i) ASSERT_NEAR(out[i], root[i], kTol) << "frame " << i / 3;
      continue;
    }
    ASSERT_EQ(c.target_path, "rotation");
    ++rotation_channels.at(j);
    ASSERT_EQ(out.size(), 4u * frames);
    for (int f = 0; f < frames; ++f) {
      const float* q = &rotations[(static_cast<size_t>(f) * joints + j) * 4];  // w, x, y, z
      const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      const float* r = &out[4 * f];  // x, y, z, w
      for (int k = 0; k < 4; ++k) ASSERT_NEAR(r[k], q[(k + 1) % 4] / n, kTol) << "frame " << f << ", joint " << j;
    }
  }
  EXPECT_EQ(rotation_channels, std::vector<int>(joints, 1));
}

void expect_matches(const std::vector<uint8_t>& bytes, bool binary, const mf_motion* m) {
  const tinygltf::Model g = parse(bytes, binary);
  EXPECT_EQ(g.asset.version, "2.0");
  expect_skeleton(g, m);
  expect_animation(g, m);
}

std::vector<uint8_t> to_memory(const mf_motion* m, int32_t format) {
  mf_gltf_options o;
  EXPECT_EQ(mf_gltf_options_init(&o), MF_OK);
  o.format = format;
  size_t needed = 0;
  const int status = mf_motion_save_gltf_to_memory(m, &o, nullptr, 0, &needed);
  EXPECT_EQ(status, MF_OK) << describe(status);
  std::vector<uint8_t> bytes(needed);
  EXPECT_EQ(mf_motion_save_gltf_to_memory(m, &o, bytes.data(), bytes.size(), &needed), MF_OK);
  return bytes;
}

MotionPtr load(const std::string& path, double length_scale) {
  mf_bvh_options o;
  EXPECT_EQ(mf_bvh_options_init(&o), MF_OK);
  o.length_scale = length_scale;
  mf_motion* m = nullptr;
  const int status = mf_motion_load_bvh(path.c_str(), &o, &m);
  EXPECT_EQ(status, MF_OK) << describe(status);
  return MotionPtr(m);
}

TEST(CApiGltf, FilesOfTheSampleReadBackInMetres) {
  const std::string dir = test::scratch_dir("capi-gltf-" + std::to_string(::getpid()));
  const MotionPtr walk = load(sample_bvh(), 0.0);  // centimetres, detected
  double scale = 0;
  ASSERT_EQ(mf_motion_get_length_scale(walk.get(), &scale), MF_OK);
  ASSERT_EQ(scale, 0.01);
  for (const char* name : {"walk.glb", "walk.GLTF"}) {
    const std::string path = dir + "/" + name;
    const int status = mf_motion_save_gltf(walk.get(), path.c_str(), nullptr);
    ASSERT_EQ(status, MF_OK) << describe(status);
    const std::vector<uint8_t> bytes = read_bytes(path);
    const bool binary = std::string(name) == "walk.glb";
    ASSERT_GT(bytes.size(), 12u);
    EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + 4) == "glTF", binary) << name;
    if (!binary) {
      EXPECT_NE(std::string(bytes.begin(), bytes.end()).find("data:application/octet-stream;base64,"),
                std::string::npos);
    }
    expect_matches(bytes, binary, walk.get());
    EXPECT_EQ(bytes, to_memory(walk.get(), binary ? MF_GLTF_BINARY : MF_GLTF_EMBEDDED)) << name;
  }
  // The unit: the same file read as metres gives 100 times the translations.
  const MotionPtr as_metres = load(sample_bvh(), 1.0);
  const tinygltf::Model cm = parse(to_memory(walk.get(), MF_GLTF_AUTO), true);
  const tinygltf::Model m = parse(to_memory(as_metres.get(), MF_GLTF_AUTO), true);
  const int root = m.animations[0].channels.back().sampler;
  const std::vector<float> cm_root = floats(cm, cm.animations[0].samplers[root].output);
  const std::vector<float> m_root = floats(m, m.animations[0].samplers[root].output);
  ASSERT_EQ(cm_root.size(), m_root.size());
  for (size_t i = 0; i < m_root.size(); ++i) EXPECT_NEAR(m_root[i], 100.0 * cm_root[i], 1e-5 * std::abs(m_root[i]));
  EXPECT_NEAR(m.nodes[1].translation[1], 100.0 * cm.nodes[1].translation[1], 1e-4);
  std::filesystem::remove_all(dir);
}

TEST(CApiGltf, RandomMotionsAndASingleFrameRoundTrip) {
  for (const auto& [frames, fps] : {std::pair<int, double>{37, 24.0}, {1, 30.0}, {90, 120.0}}) {
    const MotionPtr m = random_capi_motion(frames, fps, static_cast<uint32_t>(frames));
    expect_matches(to_memory(m.get(), MF_GLTF_BINARY), true, m.get());
    expect_matches(to_memory(m.get(), MF_GLTF_EMBEDDED), false, m.get());
  }
}

TEST(CApiGltf, TheWriterRefusesMotionsGltfCannotHold) {
  const Motion good = test::random_motion(test::small_skeleton(), 4, 30.0, 3);
  EXPECT_NO_THROW(format_gltf(good, GltfFormat::Binary));
  const auto refuses = [](const Motion& m, const std::string& text) {
    try {
      format_gltf(m, GltfFormat::Binary);
      ADD_FAILURE() << "no error, expected one with '" << text << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  };
  Motion bad = good;
  bad.root_positions[2].x() = std::numeric_limits<double>::quiet_NaN();
  refuses(bad, "not finite");
  bad = good;
  bad.rotation(1, 2).w() = std::numeric_limits<double>::infinity();
  refuses(bad, "not a finite non-zero quaternion");
  refuses(good.slice(0, 0), "no frames");
  bad = good;
  bad.root_positions[1].y() = 1e39;
  refuses(bad, "32-bit float");
  bad = good;
  bad.skeleton.offsets[3].z() = -1e40;
  refuses(bad, "32-bit float");
}

}  // namespace
}  // namespace mf::capi_test

namespace mf::capi_test {
namespace {

std::string last_error() { return mf_last_error_message(); }

// mf_motion_load: the format from the content or the name, or as asked; a
// glTF written by the library reads back (metres, no BVH layout).
TEST(CApiMotionLoad, ReadsEveryFormatByContentNameOrOption) {
  MotionPtr bvh;
  {
    mf_motion* m = nullptr;
    ASSERT_EQ(mf_motion_load(sample_bvh().c_str(), nullptr, &m), MF_OK) << last_error();
    bvh.reset(m);
  }
  EXPECT_EQ(frame_count(bvh.get()), 61);
  mf_gltf_options go;
  ASSERT_EQ(mf_gltf_options_init(&go), MF_OK);
  size_t needed = 0;
  ASSERT_EQ(mf_motion_save_gltf_to_memory(bvh.get(), &go, nullptr, 0, &needed), MF_OK);
  std::vector<uint8_t> glb(needed);
  ASSERT_EQ(mf_motion_save_gltf_to_memory(bvh.get(), &go, glb.data(), glb.size(), &needed), MF_OK);

  mf_motion_load_options o;
  ASSERT_EQ(mf_motion_load_options_init(&o), MF_OK);
  mf_motion* m = nullptr;
  ASSERT_EQ(mf_motion_load_from_memory(glb.data(), glb.size(), &o, &m), MF_OK) << last_error();
  MotionPtr gltf(m);
  double scale = 0;
  ASSERT_EQ(mf_motion_get_length_scale(gltf.get(), &scale), MF_OK);
  EXPECT_EQ(scale, 1.0);
  const std::vector<float> a = global_positions(bvh.get()), b = global_positions(gltf.get());
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) ASSERT_NEAR(a[i], b[i], 1e-5);

  // Named as FBX, it is refused by the FBX reader; a bad format value.
  o.format = MF_FORMAT_FBX;
  m = nullptr;
  EXPECT_EQ(mf_motion_load_from_memory(glb.data(), glb.size(), &o, &m), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(m, nullptr);
  EXPECT_NE(last_error().find("<memory>: not a valid FBX file"), std::string::npos) << last_error();
  o.format = 7;
  EXPECT_EQ(mf_motion_load_from_memory(glb.data(), glb.size(), &o, &m), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(last_error().find("mf_motion_load_options.format"), std::string::npos);
  o.format = MF_FORMAT_AUTO;
  const std::string garbage = "neither";
  EXPECT_EQ(mf_motion_load_from_memory(reinterpret_cast<const uint8_t*>(garbage.data()), garbage.size(), &o, &m),
            MF_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(last_error().find("cannot tell the format of <memory>"), std::string::npos) << last_error();
  EXPECT_EQ(mf_motion_load("/nonexistent/walk.glb", &o, &m), MF_ERROR_IO);
}

}  // namespace
}  // namespace mf::capi_test
