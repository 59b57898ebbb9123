// glTF input (prior/motion/gltf_reader.h), the scene conversion it shares with
// FBX (node_animation.h) and the format detection (motion_file.h). FBX files
// from Blender are read in tests/formats/blender_formats_test.sh.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "prior/motion/errors.h"
#include "prior/motion/gltf_reader.h"
#include "prior/motion/motion_bvh.h"
#include "prior/motion/motion_file.h"
#include "prior/motion/motion_gltf.h"
#include "prior/motion/node_animation.h"
#include "prior/motion/rotations.h"

namespace mf {
namespace {

const std::string kSample = std::string(MF_SOURCE_DIR) + "/samples/walk_keyframes.bvh";

Motion sample() { return read_motion(kSample, nullptr, BvhUnits{0.01}); }

Motion read(const std::vector<uint8_t>& bytes, const SceneReadOptions& options = {}) {
  return read_gltf_motion(bytes.data(), bytes.size(), "", options);
}

std::vector<uint8_t> bytes_of(const std::string& text) { return std::vector<uint8_t>(text.begin(), text.end()); }

// The message of the InputError `f` throws ("" if none).
template <class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expect_same_motion(const Motion& a, const Motion& b, double tolerance) {
  ASSERT_EQ(a.skeleton.names, b.skeleton.names);
  ASSERT_EQ(a.skeleton.parents, b.skeleton.parents);
  ASSERT_EQ(a.num_frames(), b.num_frames());
  EXPECT_EQ(a.fps, b.fps);
  for (int j = 0; j < a.num_joints(); ++j)
    EXPECT_LT((a.skeleton.offsets[j] - b.skeleton.offsets[j]).norm(), tolerance) << a.skeleton.names[j];
  double worst_angle = 0, worst_position = 0;
  for (int f = 0; f < a.num_frames(); ++f) {
    worst_position = std::max(worst_position, (a.root_positions[f] - b.root_positions[f]).norm());
    for (int j = 0; j < a.num_joints(); ++j)
      worst_angle = std::max(worst_angle, geodesic_angle(a.rotation(f, j), b.rotation(f, j)));
  }
  EXPECT_LT(worst_position, tolerance);
  EXPECT_LT(worst_angle, tolerance);
}

TEST(GltfReader, OurOutputReadsBackWithin1e5) {
  const Motion m = sample();
  for (GltfFormat format : {GltfFormat::Binary, GltfFormat::Embedded}) {
    const Motion back = read(format_gltf(m, format));
    expect_same_motion(m, back, 1e-5);
    EXPECT_EQ(back.fps, 30.0);
  }
}

TEST(GltfReader, SamplesAtAGivenRate) {
  const Motion m = sample();
  SceneReadOptions options;
  options.fps = 60;
  const Motion back = read(format_gltf(m, GltfFormat::Binary), options);
  ASSERT_EQ(back.num_frames(), 2 * m.num_frames() - 1);
  EXPECT_EQ(back.fps, 60.0);
  for (int f = 0; f < m.num_frames(); ++f) {
    EXPECT_LT((back.root_positions[2 * f] - m.root_positions[f]).norm(), 1e-5);
    EXPECT_LT(geodesic_angle(back.rotation(2 * f, 3), m.rotation(f, 3)), 1e-5);
  }
  // Between keys: the slerp of the neighbours.
  EXPECT_LT(geodesic_angle(back.rotation(1, 3), slerp(m.rotation(0, 3), m.rotation(1, 3), 0.5)), 1e-5);
}

TEST(GltfReader, PicksTheAnimationByNameOrIndex) {
  const std::vector<uint8_t> glb = format_gltf(sample(), GltfFormat::Binary);
  SceneReadOptions options;
  options.animation = "motion";
  EXPECT_EQ(read(glb, options).num_frames(), 61);
  options.animation = "run";
  EXPECT_EQ(error_of([&] { read(glb, options); }), "there is no animation named 'run': the file has 'motion'");
  options.animation = "";
  options.animation_index = 1;
  EXPECT_EQ(error_of([&] { read(glb, options); }), "there is no animation 1: the file has 1 (0 to 0)");
}

// The sample as glTF JSON, to damage.
nlohmann::json sample_json() {
  const std::vector<uint8_t> text = format_gltf(sample(), GltfFormat::Embedded);
  return nlohmann::json::parse(text.begin(), text.end());
}

TEST(GltfReader, BadFilesGetClearErrors) {
  const std::vector<uint8_t> glb = format_gltf(sample(), GltfFormat::Binary);
  const std::vector<uint8_t> truncated(glb.begin(), glb.begin() + static_cast<long>(glb.size() / 2));
  EXPECT_NE(error_of([&] { read(truncated); }).find("not a valid glTF file"), std::string::npos);
  EXPECT_NE(error_of([&] { read(bytes_of("{\"asset\": {\"version\": \"2.0\"}")); }).find("not a valid glTF file"),
            std::string::npos);

  nlohmann::json j = sample_json();
  j.erase("animations");
  EXPECT_EQ(error_of([&] { read(bytes_of(j.dump())); }), "no animation: the file has none");

  j = sample_json();
  j["animations"][0]["channels"] = nlohmann::json::array();
  EXPECT_EQ(error_of([&] { read(bytes_of(j.dump())); }), "no armature: no joints were found");

  // Hips' second child (a leg) detached: a second top joint.
  j = sample_json();
  nlohmann::json& children = j["nodes"][0]["children"];
  const int leg = children[1].get<int>();
  children.erase(1);
  const std::string two_roots = error_of([&] { read(bytes_of(j.dump())); });
  EXPECT_NE(two_roots.find("the armature has two roots: 'Hips' and '" + j["nodes"][leg]["name"].get<std::string>()),
            std::string::npos)
      << two_roots;

  j = sample_json();
  j["accessors"][1]["count"] = 2'000'000'000;
  EXPECT_NE(error_of([&] { read(bytes_of(j.dump())); }).find("more than 10000000"), std::string::npos);
  j["accessors"][1]["count"] = 1'000'000;
  EXPECT_NE(error_of([&] { read(bytes_of(j.dump())); }).find("beyond its buffer"), std::string::npos);

  j = sample_json();
  j["nodes"][2]["children"].push_back(1);
  EXPECT_NE(error_of([&] { read(bytes_of(j.dump())); }).find("node 1 ('Spine') has two parents"), std::string::npos);
  j = sample_json();
  j["nodes"][1]["children"].push_back(0);
  EXPECT_EQ(error_of([&] { read(bytes_of(j.dump())); }), "the node hierarchy has a cycle");
}

TEST(GltfReader, NanKeysAreNamed) {
  std::vector<uint8_t> glb = format_gltf(sample(), GltfFormat::Binary);
  uint32_t json_length = 0;
  std::memcpy(&json_length, glb.data() + 12, 4);
  // The buffer: 61 key times, then joint 0's rotations.
  const size_t first_rotation = 12 + 8 + json_length + 8 + 61 * 4;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(glb.data() + first_rotation, &nan, 4);
  EXPECT_EQ(error_of([&] { read(glb); }),
            "the rotation keys of node 'Hips' hold a non-finite number (NaN or infinity)");
}

TEST(GltfReader, KeyRateSnapsToWholeFrameRates) {
  EXPECT_EQ(fps_from_key_times({0.0, 1 / 30.0 + 1e-8, 2 / 30.0}), 30.0);
  EXPECT_EQ(fps_from_key_times({0.0}), 30.0);
  EXPECT_NEAR(fps_from_key_times({0.0, 0.3}), 1 / 0.3, 1e-12);
  EXPECT_NE(error_of([] { fps_from_key_times({0.0, 1e-5}); }).find("over 1000 fps"), std::string::npos);
}

// An armature object above a container joint, scaled to centimetres and
// turned Z up (an FBX from Blender): the motion is the hips' in metres, Y up.
TEST(NodeAnimation, ComposesContainersAndRemovesScaleAndAxes) {
  NodeAnimation a;
  a.names = {"Armature", "joint_Root", "Hips", "Spine"};
  a.parents = {-1, 0, 1, 2};
  a.joints = mark_joints(a.parents, {0, 1, 1, 1});
  EXPECT_EQ(a.joints, (std::vector<char>{0, 1, 1, 1}));
  a.rest.resize(4);
  a.rest[0].scale = Eigen::Vector3d::Constant(0.01);
  a.rest[2].translation = Eigen::Vector3d(0, 0, 97);
  a.rest[3].translation = Eigen::Vector3d(0, 0, 10);
  a.rest[3].rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX()));  // a bone's roll
  a.tracks.resize(4);
  KeyTrack& hips = a.tracks[2].translation;
  hips.times = {0, 0.5, 1};
  hips.values = {0, 0, 97, 0, 50, 97, 0, 100, 97};
  KeyTrack& spine = a.tracks[3].rotation;
  const Eigen::Quaterniond turn = a.rest[3].rotation * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ());
  spine.width = 4;
  spine.times = {0, 1};
  spine.values = {a.rest[3].rotation.x(), a.rest[3].rotation.y(), a.rest[3].rotation.z(), a.rest[3].rotation.w(),
                  turn.x(), turn.y(), turn.z(), turn.w()};
  a.metres_per_unit = 0.01;  // centimetres
  a.to_y_up << 1, 0, 0, 0, 0, 1, 0, -1, 0;  // Z up -> Y up
  SceneReadOptions options;
  options.fps = 2;
  const Motion m = motion_from_node_animation(a, options);
  EXPECT_EQ(m.skeleton.names, (std::vector<std::string>{"Hips", "Spine"}));
  ASSERT_EQ(m.num_frames(), 3);
  EXPECT_LT((m.root_positions[1] - Eigen::Vector3d(0, 0.0097, -0.005)).norm(), 1e-12);
  EXPECT_LT((m.skeleton.offsets[1] - Eigen::Vector3d(0, 0.001, 0)).norm(), 1e-12);
  EXPECT_LT(geodesic_angle(m.rotation(0, 1), Eigen::Quaterniond::Identity()), 1e-12);
  // The spine turned 0.3 rad about its own Z axis, which is world -Y rolled by 0.5 about X.
  EXPECT_NEAR(geodesic_angle(m.rotation(2, 1), Eigen::Quaterniond::Identity()), 0.3, 1e-12);
}

TEST(MotionFile, FormatFromContentThenName) {
  auto detect = [](const std::string& name, const std::string& head) {
    return detect_motion_format(name, reinterpret_cast<const uint8_t*>(head.data()), head.size());
  };
  EXPECT_EQ(detect("a.bvh", "glTF\x02"), MotionFormat::Gltf);
  EXPECT_EQ(detect("x", "Kaydara FBX Binary  \x00"), MotionFormat::Fbx);
  EXPECT_EQ(detect("x", "; FBX 7.4.0 project file"), MotionFormat::Fbx);
  EXPECT_EQ(detect("x.glb", "\xEF\xBB\xBF\r\nHIERARCHY\nROOT"), MotionFormat::Bvh);
  EXPECT_EQ(detect("x", "  {\"asset\""), MotionFormat::Gltf);
  EXPECT_EQ(detect("walk.FBX", ""), MotionFormat::Fbx);
  EXPECT_EQ(detect("walk.gltf", "garbage"), MotionFormat::Gltf);
  EXPECT_EQ(detect("walk.Bvh", "garbage"), MotionFormat::Bvh);
  EXPECT_NE(error_of([&] { detect("dir.fbx/walk", "garbage"); }).find("cannot tell the format of dir.fbx/walk"),
            std::string::npos);
}

}  // namespace
}  // namespace mf
