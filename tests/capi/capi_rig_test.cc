// Motions on other rigs through the C API: length units (detected or given),
// rig maps (automatic, as JSON text or a file, and their errors), and the
// learned methods and re-navigation served on a rig that is not the model's,
// with the bundled default model (skipped when it is absent).
#include <functional>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/capi/capi_test_util.h"
#include "tests/test_util.h"

namespace mf::capi_test {
namespace {

mf_motion* const kMotionSentinel = reinterpret_cast<mf_motion*>(0x5eed);

void write_text(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

std::string scratch() { return test::scratch_dir("capi-rig-" + std::to_string(::getpid())); }

// The sample with Mixamo's joint names (everything else unchanged).
std::string mixamo_sample_text() {
  std::string text = read_text(sample_bvh());
  std::vector<std::pair<std::string, std::string>> names = {
      {"Hips", "Hips"}, {"Spine", "Spine"}, {"Chest", "Spine2"}, {"Neck", "Neck"}, {"Head", "Head"}};
  for (const auto& [side, word] : {std::pair<std::string, std::string>{"L", "Left"}, {"R", "Right"}}) {
    for (const auto& [ours, theirs] : std::vector<std::pair<std::string, std::string>>{
             {"Shoulder", "Shoulder"}, {"UpperArm", "Arm"}, {"LowerArm", "ForeArm"}, {"Hand", "Hand"},
             {"UpperLeg", "UpLeg"}, {"LowerLeg", "Leg"}, {"Foot", "Foot"}, {"Toes", "ToeBase"}})
      names.emplace_back(ours + "_" + side, word + theirs);
  }
  for (const auto& [from, to] : names) {
    const std::string key = "JOINT " + from + "\n";
    const size_t at = text.find(key);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, key.size(), "JOINT mixamorig:" + to + "\n");
  }
  return text;
}

MotionPtr motion_from_text(const std::string& text, double length_scale = 0.0) {
  mf_bvh_options o;
  mf_bvh_options_init(&o);
  o.length_scale = length_scale;
  mf_motion* m = nullptr;
  const int status = mf_motion_load_bvh_from_memory(text.data(), text.size(), &o, &m);
  EXPECT_EQ(status, MF_OK) << describe(status);
  return MotionPtr(m);
}

std::string bvh_text(const mf_motion* m, double length_scale = 0.0) {
  mf_bvh_options o;
  mf_bvh_options_init(&o);
  o.length_scale = length_scale;
  size_t n = 0;
  EXPECT_EQ(mf_motion_save_bvh_to_memory(m, &o, nullptr, 0, &n), MF_OK);
  std::string text(n, '\0');
  EXPECT_EQ(mf_motion_save_bvh_to_memory(m, &o, text.data(), text.size(), &n), MF_OK);
  text.resize(n - 1);
  return text;
}

double length_scale(const mf_motion* m) {
  double s = 0;
  EXPECT_EQ(mf_motion_get_length_scale(m, &s), MF_OK);
  return s;
}

std::vector<std::string> joint_names(const mf_motion* m) {
  int32_t J = 0;
  EXPECT_EQ(mf_motion_get_joint_count(m, &J), MF_OK);
  std::vector<std::string> out;
  for (int32_t j = 0; j < J; ++j) {
    char name[256];
    EXPECT_EQ(mf_motion_get_joint_name(m, j, name, sizeof name, nullptr), MF_OK);
    out.emplace_back(name);
  }
  return out;
}

// The sample on Mixamo names, in metres.
MotionPtr mixamo_metres() {
  const MotionPtr cm = motion_from_text(mixamo_sample_text());
  return motion_from_text(bvh_text(cm.get(), 1.0));
}

// A Mixamo-named rig whose rest pose (every rotation zero) is a T-pose facing
// +Z, centimetres, two frames of that pose.
MotionPtr tpose_rig() {
  struct Joint {
    std::string name;
    int parent;
    double x, y, z;
  };
  std::vector<Joint> joints = {{"Hips", -1, 0, 95, 0}, {"Spine", 0, 0, 10, 0}, {"Spine2", 1, 0, 25, 0},
                               {"Neck", 2, 0, 20, 0},  {"Head", 3, 0, 10, 0}};
  for (int side = 0; side < 2; ++side) {
    const std::string S = side == 0 ? "Left" : "Right";
    const double x = side == 0 ? 1 : -1;
    const int base = static_cast<int>(joints.size());
    joints.push_back({S + "Shoulder", 2, x * 5, 15, 0});
    joints.push_back({S + "Arm", base, x * 12, 0, 0});
    joints.push_back({S + "ForeArm", base + 1, x * 28, 0, 0});
    joints.push_back({S + "Hand", base + 2, x * 25, 0, 0});
    joints.push_back({S + "UpLeg", 0, x * 9, -5, 0});
    joints.push_back({S + "Leg", base + 4, 0, -42, 0});
    joints.push_back({S + "Foot", base + 5, 0, -40, 0});
    joints.push_back({S + "ToeBase", base + 6, 0, -6, 12});
  }
  std::string text = "HIERARCHY\n";
  std::function<void(int, int)> write = [&](int j, int depth) {
    const std::string pad(static_cast<size_t>(depth) * 2, ' ');
    const Joint& J = joints[static_cast<size_t>(j)];
    text += pad + (J.parent < 0 ? "ROOT " : "JOINT ") + "mixamorig:" + J.name + "\n" + pad + "{\n";
    text += pad + "  OFFSET " + std::to_string(J.x) + " " + std::to_string(J.y) + " " + std::to_string(J.z) + "\n";
    text += pad + (J.parent < 0 ? "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
                                : "  CHANNELS 3 Zrotation Xrotation Yrotation\n");
    bool leaf = true;
    for (size_t c = 0; c < joints.size(); ++c)
      if (joints[c].parent == j) write(static_cast<int>(c), depth + 1), leaf = false;
    if (leaf) text += pad + "  End Site\n" + pad + "  {\n" + pad + "    OFFSET 0 5 0\n" + pad + "  }\n";
    text += pad + "}\n";
  };
  write(0, 0);
  std::string frame = "0 95 0";
  for (size_t j = 0; j < joints.size(); ++j) frame += " 0 0 0";
  text += "MOTION\nFrames: 2\nFrame Time: 0.0333333\n" + frame + "\n" + frame + "\n";
  return motion_from_text(text);
}

std::string default_model_file() { return std::string(MF_SOURCE_DIR) + "/models/motionfield-prior.mfm"; }

// The bundled model, loaded once (null when it is absent).
const mf_model* default_model() {
  static const ModelPtr model = [] {
    mf_model* m = nullptr;
    if (!std::filesystem::exists(default_model_file())) return ModelPtr();
    EXPECT_EQ(mf_model_load(default_model_file().c_str(), &m), MF_OK) << describe(MF_OK);
    return ModelPtr(m);
  }();
  return model.get();
}

// The bundled model is part of the repository: its absence is a failure.
#define REQUIRE_DEFAULT_MODEL() \
  ASSERT_NE(default_model(), nullptr) << "no bundled model at " << default_model_file()

// A fast learned method: the two-stage transformer, bundled with the model.
const char* fast_method(const mf_model* model) {
  int32_t has = 0;
  EXPECT_EQ(mf_model_has_inbetweener(model, "twostage", &has), MF_OK);
  EXPECT_EQ(has, 1) << "no bundled motionfield-twostage.mfm next to " << default_model_file();
  return "detail";
}

nlohmann::json describe_rig(const mf_model* model, const mf_motion* motion, const char* map = nullptr) {
  size_t n = 0;
  EXPECT_EQ(mf_rig_describe(model, motion, map, nullptr, 0, &n), MF_OK) << describe(MF_OK);
  std::string text(n, '\0');
  EXPECT_EQ(mf_rig_describe(model, motion, map, text.data(), text.size(), &n), MF_OK);
  text.resize(n - 1);
  return nlohmann::json::parse(text);
}

::testing::AssertionResult Fails(int got, int status, const std::string& text) {
  if (got != status)
    return ::testing::AssertionFailure() << "status " << got << ", expected " << status << ": "
                                         << mf_last_error_message();
  if (std::string(mf_last_error_message()).find(text) == std::string::npos)
    return ::testing::AssertionFailure() << "message '" << mf_last_error_message() << "' lacks '" << text << "'";
  return ::testing::AssertionSuccess();
}

TEST(CApiRig, LengthUnitIsDetectedFromTheSkeletonOrGiven) {
  mf_motion* raw = nullptr;
  ASSERT_EQ(mf_motion_load_bvh(sample_bvh().c_str(), nullptr, &raw), MF_OK);
  const MotionPtr cm(raw);
  EXPECT_EQ(length_scale(cm.get()), 0.01);
  // The same motion written in metres reads back as metres, same positions.
  const std::string metres_text = bvh_text(cm.get(), 1.0);
  const MotionPtr metres = motion_from_text(metres_text);
  EXPECT_EQ(length_scale(metres.get()), 1.0);
  // Written back in its own unit: the chest's 14 cm as 0.14.
  EXPECT_NE(bvh_text(metres.get()).find("OFFSET 0.14 0 0"), std::string::npos);
  const std::vector<float> a = root_positions(cm.get()), b = root_positions(metres.get());
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i], b[i], 1e-5f);
  // A given scale wins; motions from arrays are in centimetres.
  EXPECT_EQ(length_scale(motion_from_text(metres_text, 0.01).get()), 0.01);
  EXPECT_EQ(length_scale(random_capi_motion(3, 30.0, 1).get()), 0.01);

  double s = 0;
  ASSERT_EQ(mf_length_unit_scale("in", &s), MF_OK);
  EXPECT_DOUBLE_EQ(s, 0.0254);
  ASSERT_EQ(mf_length_unit_scale("m", &s), MF_OK);
  EXPECT_EQ(s, 1.0);
  EXPECT_TRUE(Fails(mf_length_unit_scale("furlong", &s), MF_ERROR_INVALID_ARGUMENT, "cm, m, mm, in, ft or asf"));
  EXPECT_EQ(s, 1.0);
  EXPECT_TRUE(Fails(mf_motion_get_length_scale(nullptr, &s), MF_ERROR_INVALID_ARGUMENT, "NULL"));
}

TEST(CApiRig, DescribeShowsTheUnitAndTheMap) {
  REQUIRE_DEFAULT_MODEL();
  const MotionPtr user = mixamo_metres();
  const nlohmann::json d = describe_rig(default_model(), user.get());
  EXPECT_EQ(d["unit"], "m");
  EXPECT_EQ(d["length_scale"], 1.0);
  EXPECT_EQ(d["unit_detected"], true);
  EXPECT_EQ(d["unit_from_file"], false);
  EXPECT_EQ(d["joints"], 21);
  EXPECT_EQ(d["map"]["mixamorig:LeftArm"], "UpperArm_L");
  EXPECT_EQ(d["map"]["mixamorig:RightToeBase"], "Toes_R");
  EXPECT_EQ(d["how"]["UpperArm_L"], "name");
  EXPECT_TRUE(d["unmapped_user_joints"].empty());
  EXPECT_EQ(d["model_joints"].size(), 21u);
  EXPECT_EQ(d["retargeting"], true);
  // The sample's rest (every bone along its local X) is no T or A pose.
  EXPECT_EQ(d["anatomy"], "known frames");
  const MotionPtr tpose = tpose_rig();
  EXPECT_EQ(describe_rig(default_model(), tpose.get())["anatomy"], "rest pose");
  // A map's entries say so.
  const nlohmann::json m = describe_rig(default_model(), user.get(), R"({"mixamorig:Spine2": "Chest"})");
  EXPECT_EQ(m["how"]["Chest"], "map file");

  char small[4];
  size_t needed = 0;
  EXPECT_TRUE(Fails(mf_rig_describe(default_model(), user.get(), nullptr, small, sizeof small, &needed),
                    MF_ERROR_BUFFER_TOO_SMALL, ""));
  EXPECT_GT(needed, sizeof small);
  EXPECT_TRUE(Fails(mf_rig_describe(nullptr, user.get(), nullptr, nullptr, 0, &needed), MF_ERROR_MODEL, "model"));
  EXPECT_TRUE(Fails(mf_rig_describe(default_model(), user.get(), "{not json", nullptr, 0, &needed),
                    MF_ERROR_INVALID_ARGUMENT, "rig map: not valid JSON"));
  // Bad buffer arguments are refused before the map is read: the broken map is not what the error names.
  EXPECT_TRUE(Fails(mf_rig_describe(default_model(), user.get(), "{not json", nullptr, 10, &needed),
                    MF_ERROR_INVALID_ARGUMENT, "the output buffer is NULL but its capacity is not 0"));
  EXPECT_TRUE(Fails(mf_rig_describe(default_model(), user.get(), "{not json", nullptr, 0, nullptr),
                    MF_ERROR_INVALID_ARGUMENT, "needs a non-NULL `needed`"));
}

TEST(CApiRig, LearnedMethodsServeAnotherRig) {
  REQUIRE_DEFAULT_MODEL();
  const MotionPtr user = mixamo_metres();
  const int32_t keys[] = {0, 20, 40, 60};
  mf_task_options o;
  mf_task_options_init(&o);
  o.method = fast_method(default_model());
  mf_motion* raw = nullptr;
  ASSERT_EQ(mf_inbetween(default_model(), user.get(), keys, 4, &o, &raw), MF_OK) << describe(MF_OK);
  const MotionPtr out(raw);
  EXPECT_EQ(joint_names(out.get()), joint_names(user.get()));
  EXPECT_EQ(frame_count(out.get()), 61);
  const std::vector<float> rin = rotations(user.get()), rout = rotations(out.get());
  const std::vector<float> pin = root_positions(user.get()), pout = root_positions(out.get());
  for (float v : rout) ASSERT_TRUE(std::isfinite(v));
  const size_t per_frame = rin.size() / 61;
  for (int32_t k : keys) {
    for (size_t i = 0; i < per_frame; ++i) EXPECT_EQ(rout[k * per_frame + i], rin[k * per_frame + i]) << k;
    for (int c = 0; c < 3; ++c) EXPECT_EQ(pout[3 * k + c], pin[3 * k + c]) << k;
  }
  // Written back in the input's unit (metres) with its joint names.
  EXPECT_EQ(length_scale(out.get()), 1.0);
  EXPECT_NE(bvh_text(out.get()).find("JOINT mixamorig:LeftForeArm"), std::string::npos);

  // Gap filling at another frame rate (25 fps), with a rig map as text.
  std::string text = bvh_text(user.get());
  const size_t at = text.find("Frame Time:");
  text.replace(at, text.find('\n', at) - at, "Frame Time: 0.04");
  const MotionPtr slow = motion_from_text(text);
  o.rig_map = R"({"mixamorig:Spine2": "Chest"})";
  ASSERT_EQ(mf_fill(default_model(), slow.get(), 10, 40, &o, &raw), MF_OK) << describe(MF_OK);
  const MotionPtr filled(raw);
  EXPECT_EQ(frame_count(filled.get()), 61);
  double fps = 0;
  ASSERT_EQ(mf_motion_get_fps(filled.get(), &fps), MF_OK);
  EXPECT_EQ(fps, 25.0);
  EXPECT_EQ(rotations(filled.get())[9 * per_frame], rotations(slow.get())[9 * per_frame]);
}

int joint_index(const mf_motion* m, const std::string& name) {
  const std::vector<std::string> names = joint_names(m);
  const auto it = std::find(names.begin(), names.end(), name);
  EXPECT_NE(it, names.end()) << name;
  return static_cast<int>(it - names.begin());
}

// Partial keys, a target, a contact pin and an alternative on another rig at
// another frame rate (Mixamo names, metres, 25 fps): the solve runs on the
// model's rig and rate and every constraint is made exact on the user's.
TEST(CApiRig, ConstraintsServeAnotherRigAndRate) {
  REQUIRE_DEFAULT_MODEL();
  std::string text = bvh_text(mixamo_metres().get());
  const size_t at = text.find("Frame Time:");
  text.replace(at, text.find('\n', at) - at, "Frame Time: 0.04");
  const MotionPtr user = motion_from_text(text);
  const int J = static_cast<int>(joint_names(user.get()).size());
  const int hand = joint_index(user.get(), "mixamorig:RightHand"), foot = joint_index(user.get(), "mixamorig:LeftFoot");
  const int arm = joint_index(user.get(), "mixamorig:LeftArm"), fore = joint_index(user.get(), "mixamorig:LeftForeArm");
  const std::vector<float> p_in = global_positions(user.get());
  char json[1024];
  std::snprintf(json, sizeof json, R"({"keys": [{"frame": 0}, {"frame": 60},
      {"frame": 30, "joints": ["mixamorig:LeftArm", "mixamorig:LeftForeArm"]}],
      "targets": [{"frame": 45, "joint": "mixamorig:RightHand", "position": [%.6f, %.6f, %.6f]}],
      "contacts": [{"joint": "mixamorig:LeftFoot", "first": 18, "last": 26}]})",
                p_in[(45 * J + hand) * 3], p_in[(45 * J + hand) * 3 + 1] + 0.1, p_in[(45 * J + hand) * 3 + 2]);
  mf_constraints* c = nullptr;
  ASSERT_EQ(mf_constraints_parse_json(json, std::strlen(json), &c), MF_OK) << describe(MF_OK);
  mf_task_options o;
  mf_task_options_init(&o);
  o.method = "nemf";
  mf_solution* s = nullptr;
  const int status = mf_solve(default_model(), user.get(), c, 1, &o, &s);
  mf_constraints_destroy(c);
  ASSERT_EQ(status, MF_OK) << describe(status);
  std::vector<std::vector<float>> pos;
  const std::vector<float> qi = rotations(user.get());
  for (int i = 0; i < 2; ++i) {
    mf_motion* raw = nullptr;
    ASSERT_EQ(mf_solution_get_motion(s, i, &raw), MF_OK);
    const MotionPtr out(raw);
    EXPECT_EQ(joint_names(out.get()), joint_names(user.get()));
    double fps = 0;
    ASSERT_EQ(mf_motion_get_fps(out.get(), &fps), MF_OK);
    EXPECT_EQ(fps, 25.0);
    const std::vector<float> q = rotations(out.get());
    ASSERT_EQ(q.size(), qi.size());
    for (int k : {0, 60})
      for (int v = 0; v < J * 4; ++v) ASSERT_EQ(q[k * J * 4 + v], qi[k * J * 4 + v]) << "solution " << i << " key " << k;
    for (int j : {arm, fore})
      for (int v = 0; v < 4; ++v) EXPECT_EQ(q[(30 * J + j) * 4 + v], qi[(30 * J + j) * 4 + v]) << "partial key joint " << j;
    const std::vector<float> p = global_positions(out.get());
    double d = 0;
    for (int v = 0; v < 3; ++v) {
      const double goal = p_in[(45 * J + hand) * 3 + v] + (v == 1 ? 0.1 : 0.0);
      d += std::pow(p[(45 * J + hand) * 3 + v] - goal, 2);
    }
    EXPECT_LT(std::sqrt(d), 0.005) << "solution " << i << ": the hand is " << std::sqrt(d) * 100 << " cm from its target";
    double slide = 0;
    for (int f = 19; f <= 26; ++f) {
      double e = 0;
      for (int v = 0; v < 3; ++v) e += std::pow(p[(f * J + foot) * 3 + v] - p[(18 * J + foot) * 3 + v], 2);
      slide = std::max(slide, std::sqrt(e));
    }
    EXPECT_LT(slide, 1e-3) << "solution " << i << ": the pinned foot moves " << slide * 100 << " cm";
    pos.push_back(p);
  }
  mf_solution_destroy(s);
  double sum = 0;
  for (size_t v = 0; v < pos[0].size(); v += 3)
    sum += std::sqrt(std::pow(pos[0][v] - pos[1][v], 2) + std::pow(pos[0][v + 1] - pos[1][v + 1], 2) +
                     std::pow(pos[0][v + 2] - pos[1][v + 2], 2));
  EXPECT_GT(sum / (pos[0].size() / 3), 0.002) << "the alternative differs by less than 2 mm";

  // Without a whole-pose key there is nothing to retarget the other joints from.
  const std::string root_only = R"({"keys": [{"frame": 0, "root": "both"}, {"frame": 60, "root": "both",
      "joints": ["mixamorig:LeftArm"]}]})";
  ASSERT_EQ(mf_constraints_parse_json(root_only.data(), root_only.size(), &c), MF_OK) << describe(MF_OK);
  s = nullptr;
  EXPECT_TRUE(Fails(mf_solve(default_model(), user.get(), c, 0, &o, &s), MF_ERROR_INVALID_ARGUMENT,
                    "at least one key must give the whole pose"));
  EXPECT_EQ(s, nullptr);
  mf_constraints_destroy(c);
}

TEST(CApiRig, BadRigMapsFailWithTheirMessage) {
  REQUIRE_DEFAULT_MODEL();
  const MotionPtr user = mixamo_metres();
  const int32_t keys[] = {0, 60};
  const std::string dir = scratch();
  mf_task_options o;
  mf_task_options_init(&o);
  o.method = fast_method(default_model());
  mf_motion* out = kMotionSentinel;

  o.rig_map = "[1, 2";
  EXPECT_TRUE(Fails(mf_inbetween(default_model(), user.get(), keys, 2, &o, &out), MF_ERROR_INVALID_ARGUMENT,
                    "rig map: not valid JSON"));
  o.rig_map = R"({"Nobody": "Hips"})";
  EXPECT_TRUE(Fails(mf_inbetween(default_model(), user.get(), keys, 2, &o, &out), MF_ERROR_INVALID_ARGUMENT,
                    "the motion has no joint named 'Nobody'"));
  // Both a text and a file.
  const std::string file = dir + "/map.json";
  write_text(file, R"({"mixamorig:Hips": "NoSuchJoint"})");
  o.rig_map = R"({"mixamorig:Spine2": "Chest"})";
  o.rig_map_path = file.c_str();
  EXPECT_TRUE(Fails(mf_inbetween(default_model(), user.get(), keys, 2, &o, &out), MF_ERROR_INVALID_ARGUMENT,
                    "not both"));
  // Errors in a file name it.
  o.rig_map = nullptr;
  EXPECT_TRUE(Fails(mf_inbetween(default_model(), user.get(), keys, 2, &o, &out), MF_ERROR_INVALID_ARGUMENT,
                    file + ": rig map: the model has no joint named 'NoSuchJoint'"));
  const std::string missing = dir + "/missing.json";
  o.rig_map_path = missing.c_str();
  EXPECT_TRUE(Fails(mf_inbetween(default_model(), user.get(), keys, 2, &o, &out), MF_ERROR_IO, missing));
  EXPECT_EQ(out, kMotionSentinel);
  // Re-navigation reads the same options.
  const float path[] = {0, 0, 1, 0};
  EXPECT_TRUE(Fails(mf_renav(default_model(), user.get(), path, 2, nullptr, &o, &out), MF_ERROR_IO, missing));
  EXPECT_EQ(out, kMotionSentinel);
  std::filesystem::remove_all(dir);
}

TEST(CApiRig, RenavigatesAReferenceOnAnotherRig) {
  REQUIRE_DEFAULT_MODEL();
  const MotionPtr user = mixamo_metres();
  std::vector<float> path;
  for (int i = 0; i < 40; ++i) path.insert(path.end(), {0.04f * i, 0.01f * i});
  mf_motion* raw = nullptr;
  ASSERT_EQ(mf_renav(default_model(), user.get(), path.data(), 40, nullptr, nullptr, &raw), MF_OK)
      << describe(MF_OK);
  const MotionPtr out(raw);
  EXPECT_EQ(joint_names(out.get()), joint_names(user.get()));
  EXPECT_EQ(frame_count(out.get()), 40);
  const std::vector<float> root = root_positions(out.get());
  for (float v : root) ASSERT_TRUE(std::isfinite(v));
  EXPECT_NEAR(root[0], 0.0f, 1e-4f);  // starts at the path's first point
  EXPECT_NEAR(root[2], 0.0f, 1e-4f);
  // and travels along +x. The path (1.22 m/s, 90 degrees off the sample's own +z) is 5.3 %
  // slower than the sample (1.29 m/s on this rig), so the reference is played at 0.947x
  // (mf::reference_pace). Without that the solver traded the path for the reference's
  // style and ended at x = 0.49 m with an earlier prior; with it, 1.37 m. At path weight 1
  // the energy preferred a slower walk to the path here (x = 0.47 m); path weight 2 follows
  // it (renav-bench: path error 33 % lower). The bound asks for more than half the path.
  // renav-bench measures path following at other paces on longer references
  // (docs/BENCHMARKS.md, "Re-navigation").
  EXPECT_GT(root[3 * 39], 0.8f) << "the root ends at x = " << root[3 * 39] << " m, z = " << root[3 * 39 + 2]
                                << " m; the path ends at x = 1.56 m, z = 0.39 m";
}

TEST(CApiRig, WithoutARigAnatomyOnlyTheModelsRigIsServed) {
  REQUIRE_DEFAULT_MODEL();
  // From memory: no anatomy.
  const std::string bytes = read_text(default_model_file());
  mf_model* raw = nullptr;
  ASSERT_EQ(mf_model_load_from_memory(bytes.data(), bytes.size(), &raw), MF_OK);
  const ModelPtr from_memory(raw);
  const MotionPtr user = mixamo_metres();
  const int32_t keys[] = {0, 60};
  mf_task_options o;
  mf_task_options_init(&o);
  o.method = "nemf";
  mf_motion* out = kMotionSentinel;
  EXPECT_TRUE(Fails(mf_inbetween(from_memory.get(), user.get(), keys, 2, &o, &out), MF_ERROR_INVALID_ARGUMENT,
                    "no rig anatomy"));
  EXPECT_EQ(describe_rig(from_memory.get(), user.get())["retargeting"], false);

  // A broken anatomy file next to the model: the model loads, other rigs fail naming it.
  const std::string dir = scratch();
  std::filesystem::copy_file(tiny_model_path(), dir + "/motionfield-prior.mfm");
  write_text(dir + "/motionfield-rig.json", "{ broken");
  ASSERT_EQ(mf_model_load((dir + "/motionfield-prior.mfm").c_str(), &raw), MF_OK) << describe(MF_OK);
  const ModelPtr broken(raw);
  mf_motion* sample = nullptr;
  ASSERT_EQ(mf_motion_load_bvh(sample_bvh().c_str(), nullptr, &sample), MF_OK);
  const MotionPtr walk(sample);
  EXPECT_TRUE(Fails(mf_inbetween(broken.get(), walk.get(), keys, 2, &o, &out), MF_ERROR_MODEL,
                    "motionfield-rig.json"));
  EXPECT_EQ(out, kMotionSentinel);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mf::capi_test
