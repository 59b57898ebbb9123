// Rig maps, unit detection and retargeting (prior/rig/), the synthetic rigs of
// the benchmark (bench/synthetic_rigs.h) and the model-rig adapter of the tasks
// (tasks/context/model_rig.h). Motion on the model's rig: the hand-made sample walk.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>

#include "bench/foreign_data.h"
#include "bench/synthetic_rigs.h"
#include "prior/data/dataset.h"
#include "prior/model/model_file.h"
#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/motion/motion_bvh.h"
#include "prior/motion/rotations.h"
#include "prior/rig/mirror.h"
#include "prior/rig/retarget.h"
#include "prior/rig/rig_map.h"
#include "prior/rig/units.h"
#include "tasks/constraints/interpolation_fill.h"
#include "tasks/context/ground_level.h"
#include "tasks/context/model_rig.h"
#include "tests/runtime_test_util.h"
#include "tests/test_util.h"

namespace mf {
namespace {

const Motion& sample() {
  static const Motion m = read_motion(std::string(MF_SOURCE_DIR) + "/samples/walk_keyframes.bvh");
  return m;
}
const RigAnatomy& sample_anatomy() {
  static const RigAnatomy a = estimate_anatomy(sample(), find_rig_parts(sample().skeleton));
  return a;
}

double max_angle_deg(const Motion& a, const Motion& b, int* where = nullptr) {
  double worst = 0;
  for (int f = 0; f < a.num_frames(); ++f)
    for (int j = 0; j < a.num_joints(); ++j) {
      const double d = geodesic_angle(a.rotation(f, j).normalized(), b.rotation(f, j).normalized()) * 180 / M_PI;
      if (d > worst) worst = d, where ? *where = j : 0;
    }
  return worst;
}
double max_root_diff(const Motion& a, const Motion& b) {
  double worst = 0;
  for (int f = 0; f < a.num_frames(); ++f) worst = std::max(worst, (a.root_positions[f] - b.root_positions[f]).norm());
  return worst;
}

TEST(RigMap, SampleRigFindsEveryPart) {
  const RigParts p = find_rig_parts(sample().skeleton);
  EXPECT_TRUE(p.missing().empty());
  const Skeleton& s = sample().skeleton;
  EXPECT_EQ(s.names[p.hips], "Hips");
  EXPECT_EQ(s.names[p.chest], "Chest");
  ASSERT_EQ(p.spine.size(), 1u);
  EXPECT_EQ(s.names[p.spine[0]], "Spine");
  EXPECT_EQ(s.names[p.head], "Head");
  EXPECT_EQ(s.names[p.neck], "Neck");
  EXPECT_EQ(s.names[p.arms[0].upper], "UpperArm_L");
  EXPECT_EQ(s.names[p.arms[1].hand], "Hand_R");
  EXPECT_EQ(s.names[p.arms[0].shoulder], "Shoulder_L");
  EXPECT_EQ(s.names[p.legs[1].shin], "LowerLeg_R");
  EXPECT_EQ(s.names[p.legs[0].toe], "Toes_L");
}

TEST(RigMap, NameSides) {
  EXPECT_EQ(name_side("mixamorig:LeftForeArm"), 0);
  EXPECT_EQ(name_side("RightHand"), 1);
  EXPECT_EQ(name_side("upperarm_l"), 0);
  EXPECT_EQ(name_side("DEF-upper_arm.R"), 1);
  EXPECT_EQ(name_side("L_Elbow"), 0);
  EXPECT_EQ(name_side("LHipJoint"), 0);
  EXPECT_EQ(name_side("Bip01 R Thigh"), 1);
  EXPECT_EQ(name_side("Spine1"), -1);
  EXPECT_EQ(name_side("Head"), -1);
}

// Every convention maps the model's joints to the variant's renamed ones.
TEST(RigMap, EveryConventionMapsToTheModel) {
  for (const bench::RigVariant& v : bench::standard_rig_variants()) {
    SCOPED_TRACE(v.name);
    const bench::VariantMotion vm = bench::make_variant(sample(), sample_anatomy(), v);
    const RigMap map = map_rig(vm.motion.skeleton, sample().skeleton);
    const Skeleton& user = vm.motion.skeleton;
    const Skeleton& model = sample().skeleton;
    for (int m = 0; m < model.num_joints(); ++m) {
      ASSERT_GE(map.user_of_model[m], 0) << model.names[m];
      // Side and kind agree: the user joint's name side is the model joint's.
      EXPECT_EQ(name_side(user.names[map.user_of_model[m]]), name_side(model.names[m]))
          << model.names[m] << " -> " << user.names[map.user_of_model[m]];
    }
    EXPECT_EQ(user.names[map.user_of_model[model.find("Hand_L")]].find("orearm"), std::string::npos);
  }
}

TEST(RigMap, MapFileOverridesAndErrors) {
  const bench::VariantMotion vm = bench::make_variant(sample(), sample_anatomy(), bench::rig_variant("mixamo"));
  const Skeleton& user = vm.motion.skeleton;
  const Skeleton& model = sample().skeleton;
  // Unmapping the neck and giving the spine to the extra joint.
  const RigMap m = map_rig(user, model, R"({"mixamorig:Neck": null, "mixamorig:Spine1": "Spine"})");
  EXPECT_EQ(m.user_of_model[model.find("Neck")], -1);
  EXPECT_EQ(user.names[m.user_of_model[model.find("Spine")]], "mixamorig:Spine1");
  EXPECT_EQ(m.how[model.find("Spine")], "map file");
  auto message = [&](const std::string& json) {
    try {
      map_rig(user, model, json);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(R"({"NoSuchJoint": "Hips"})").find("no joint named 'NoSuchJoint'"), std::string::npos);
  EXPECT_NE(message(R"({"mixamorig:Hips": "Pelvis"})").find("model has no joint named 'Pelvis'"), std::string::npos);
  EXPECT_NE(message(R"({"mixamorig:Hips": "Hips", "mixamorig:Hips": "Spine"})").find("mapped twice"), std::string::npos);
  EXPECT_NE(message(R"({"mixamorig:Spine": "Hips", "mixamorig:Spine1": "Hips"})").find("two user joints"),
            std::string::npos);
  EXPECT_NE(message("{\"a\": ").find("not valid JSON"), std::string::npos);
  EXPECT_NE(message("[1, 2]").find("expected a JSON object"), std::string::npos);
  EXPECT_NE(message(R"({"mixamorig:LeftHand": null})").find("missing left hand"), std::string::npos);
  // The map must nest like the model: a hand above the forearm is refused.
  EXPECT_NE(message(R"({"mixamorig:LeftArm": "Hand_L", "mixamorig:LeftHand": "UpperArm_L"})").find("not above it"),
            std::string::npos);
}

// A skeleton from a list of (name, parent name) with unit bones along -Y.
Skeleton named_skeleton(const std::vector<std::pair<std::string, std::string>>& joints) {
  Skeleton s;
  for (const auto& [name, parent] : joints) {
    s.names.push_back(name);
    s.parents.push_back(parent.empty() ? -1 : s.find(parent));
    s.offsets.emplace_back(0, parent.empty() ? 0.0 : -0.1, 0);
  }
  s.validate();
  return s;
}

TEST(RigMap, CmuAndUnrealLayouts) {
  // cgspeed's CMU conversion: hip joints between the hips and the thighs, two necks, fingers.
  std::vector<std::pair<std::string, std::string>> cmu = {
      {"Hips", ""}, {"LHipJoint", "Hips"}, {"LeftUpLeg", "LHipJoint"}, {"LeftLeg", "LeftUpLeg"},
      {"LeftFoot", "LeftLeg"}, {"LeftToeBase", "LeftFoot"}, {"RHipJoint", "Hips"}, {"RightUpLeg", "RHipJoint"},
      {"RightLeg", "RightUpLeg"}, {"RightFoot", "RightLeg"}, {"RightToeBase", "RightFoot"}, {"LowerBack", "Hips"},
      {"Spine", "LowerBack"}, {"Spine1", "Spine"}, {"Neck", "Spine1"}, {"Neck1", "Neck"}, {"Head", "Neck1"},
      {"LeftShoulder", "Spine1"}, {"LeftArm", "LeftShoulder"}, {"LeftForeArm", "LeftArm"}, {"LeftHand", "LeftForeArm"},
      {"LeftFingerBase", "LeftHand"}, {"LeftHandIndex1", "LeftFingerBase"}, {"LThumb", "LeftHand"},
      {"RightShoulder", "Spine1"}, {"RightArm", "RightShoulder"}, {"RightForeArm", "RightArm"},
      {"RightHand", "RightForeArm"}, {"RightFingerBase", "RightHand"}, {"RThumb", "RightHand"}};
  const Skeleton c = named_skeleton(cmu);
  const RigParts p = find_rig_parts(c);
  EXPECT_TRUE(p.missing().empty());
  EXPECT_EQ(c.names[p.hips], "Hips");
  EXPECT_EQ(c.names[p.legs[0].thigh], "LeftUpLeg");
  EXPECT_EQ(c.names[p.legs[1].toe], "RightToeBase");
  EXPECT_EQ(c.names[p.chest], "Spine1");
  EXPECT_EQ(c.names[p.neck], "Neck");
  EXPECT_EQ(c.names[p.arms[0].hand], "LeftHand");
  EXPECT_EQ(c.names[p.arms[1].shoulder], "RightShoulder");
  // The Unreal mannequin: a root with IK helpers beside the pelvis, twist bones.
  std::vector<std::pair<std::string, std::string>> ue = {{"root", ""}, {"pelvis", "root"}, {"spine_01", "pelvis"},
      {"spine_02", "spine_01"}, {"spine_03", "spine_02"}, {"clavicle_l", "spine_03"}, {"upperarm_l", "clavicle_l"},
      {"lowerarm_l", "upperarm_l"}, {"hand_l", "lowerarm_l"}, {"index_01_l", "hand_l"}, {"lowerarm_twist_01_l", "lowerarm_l"},
      {"clavicle_r", "spine_03"}, {"upperarm_r", "clavicle_r"}, {"lowerarm_r", "upperarm_r"}, {"hand_r", "lowerarm_r"},
      {"neck_01", "spine_03"}, {"head", "neck_01"}, {"thigh_l", "pelvis"}, {"calf_l", "thigh_l"}, {"foot_l", "calf_l"},
      {"ball_l", "foot_l"}, {"thigh_twist_01_l", "thigh_l"}, {"thigh_r", "pelvis"}, {"calf_r", "thigh_r"},
      {"foot_r", "calf_r"}, {"ball_r", "foot_r"}, {"ik_foot_root", "root"}, {"ik_foot_l", "ik_foot_root"},
      {"ik_hand_root", "root"}, {"ik_hand_gun", "ik_hand_root"}, {"ik_hand_l", "ik_hand_gun"}};
  const Skeleton u = named_skeleton(ue);
  const RigParts q = find_rig_parts(u);
  EXPECT_TRUE(q.missing().empty());
  EXPECT_EQ(u.names[q.hips], "pelvis");
  EXPECT_EQ(u.names[q.chest], "spine_03");
  ASSERT_EQ(q.spine.size(), 2u);
  EXPECT_EQ(u.names[q.legs[0].foot], "foot_l");
  EXPECT_EQ(u.names[q.arms[0].fore], "lowerarm_l");
  EXPECT_EQ(u.names[q.arms[1].hand], "hand_r");
  // SMPL's FBX names carry an "m_avg_" prefix.
  EXPECT_EQ(name_side("m_avg_L_Hip"), 0);
}

TEST(RigMap, CmuAsfNamesMapByName) {
  // CMU's original ASF names, one-letter sides glued to the part (the layout
  // of cmu-daz/16_01.bvh in the foreign capture).
  std::vector<std::pair<std::string, std::string>> asf = {
      {"hip", ""}, {"lhipjoint", "hip"}, {"lfemur", "lhipjoint"}, {"ltibia", "lfemur"}, {"lfoot", "ltibia"},
      {"ltoes", "lfoot"}, {"rhipjoint", "hip"}, {"rfemur", "rhipjoint"}, {"rtibia", "rfemur"}, {"rfoot", "rtibia"},
      {"rtoes", "rfoot"}, {"lowerback", "hip"}, {"upperback", "lowerback"}, {"thorax", "upperback"},
      {"lowerneck", "thorax"}, {"upperneck", "lowerneck"}, {"head", "upperneck"}, {"lclavicle", "thorax"},
      {"lhumerus", "lclavicle"}, {"lradius", "lhumerus"}, {"lwrist", "lradius"}, {"lhand", "lwrist"},
      {"lfingers", "lhand"}, {"lthumb", "lwrist"}, {"rclavicle", "thorax"}, {"rhumerus", "rclavicle"},
      {"rradius", "rhumerus"}, {"rwrist", "rradius"}, {"rhand", "rwrist"}, {"rfingers", "rhand"},
      {"rthumb", "rwrist"}};
  const Skeleton c = named_skeleton(asf);
  const RigParts p = find_rig_parts(c);
  EXPECT_TRUE(p.missing().empty());
  EXPECT_EQ(c.names[p.hips], "hip");
  EXPECT_EQ(c.names[p.chest], "thorax");
  EXPECT_EQ(c.names[p.legs[0].thigh], "lfemur");
  EXPECT_EQ(c.names[p.legs[1].shin], "rtibia");
  EXPECT_EQ(c.names[p.legs[0].foot], "lfoot");
  EXPECT_EQ(c.names[p.arms[0].upper], "lhumerus");
  EXPECT_EQ(c.names[p.arms[1].fore], "rradius");
  EXPECT_EQ(c.names[p.arms[0].hand], "lwrist");
  EXPECT_EQ(name_side("lfemur"), 0);
  EXPECT_EQ(name_side("rhipjoint"), 1);
  EXPECT_EQ(name_side("lowerback"), -1);  // not "l" + "owerback"
  EXPECT_EQ(name_side("radius"), -1);
  EXPECT_NO_THROW(mirror_counterparts(c));
}

TEST(RigMap, UnmappableRigListsWhatWasFound) {
  Skeleton s;
  s.names = {"a", "b"};
  s.parents = {-1, 0};
  s.offsets = {Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 1, 0)};
  try {
    map_rig(s, sample().skeleton);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("missing hips"), std::string::npos) << m;
    EXPECT_NE(m.find("rig map"), std::string::npos) << m;
  }
}

TEST(RigMap, ShapeFindsLimbJointsWithoutPartNames) {
  // Sides named, parts not: "L_bone1".."L_bone4" along each leg and arm.
  Skeleton s = sample().skeleton;
  int count = 0;
  for (std::string& n : s.names) {
    for (const char* part : {"UpperArm", "LowerArm", "Hand", "UpperLeg", "LowerLeg", "Foot", "Toes"}) {
      const std::string p = part;
      if (n.rfind(p + "_", 0) == 0) n = n.substr(p.size() + 1) + "_seg" + std::to_string(++count);
    }
  }
  s.validate();
  const RigMap map = map_rig(s, sample().skeleton);
  const Skeleton& model = sample().skeleton;
  for (const char* j : {"UpperArm_L", "LowerArm_L", "Hand_L", "UpperLeg_R", "LowerLeg_R", "Foot_R", "Toes_R"}) {
    ASSERT_GE(map.user_of_model[model.find(j)], 0) << j;
    EXPECT_EQ(map.user_of_model[model.find(j)], model.find(j)) << j;
    EXPECT_EQ(map.how[model.find(j)], "shape") << j;
  }
}

TEST(Units, DetectsTheFileUnit) {
  for (const auto& [name, metres] : std::vector<std::pair<std::string, double>>{
           {"cm", 0.01}, {"m", 1.0}, {"in", 0.0254}, {"mm", 0.001}, {"asf", 0.0254 / 0.45}}) {
    Skeleton s = sample().skeleton;
    for (auto& o : s.offsets) o /= metres;  // metres -> file units
    bool detected = false;
    const LengthUnit u = detect_length_unit(s, &detected);
    EXPECT_TRUE(detected);
    EXPECT_EQ(u.name, name);
  }
  bool detected = true;
  Skeleton tiny;
  tiny.names = {"root"};
  tiny.parents = {-1};
  tiny.offsets = {Eigen::Vector3d::Zero()};
  EXPECT_EQ(detect_length_unit(tiny, &detected).name, "cm");
  EXPECT_FALSE(detected);
  EXPECT_DOUBLE_EQ(length_unit_from_name("in").metres, 0.0254);
  EXPECT_THROW(length_unit_from_name("furlong"), InputError);
}

// The variant is the sample rewritten onto another rig; retargeting it to the
// model's rig gives the sample back (exactly, up to the BVH text's digits).
TEST(Retarget, VariantsRetargetToTheOriginal) {
  for (const bench::RigVariant& v0 : bench::standard_rig_variants()) {
    bench::RigVariant v = v0;
    v.fps = 0;  // same frames as the sample
    SCOPED_TRACE(v.name);
    const bench::VariantMotion vm = bench::make_variant(sample(), sample_anatomy(), v);
    RigMap map = map_rig(vm.motion.skeleton, sample().skeleton);
    RigAnatomy ua = estimate_anatomy(vm.motion, map.user_parts);
    const Retargeter r(vm.motion.skeleton, sample().skeleton, map, ua, sample_anatomy());
    EXPECT_NEAR(r.scale(), 1.0 / v.scale, 1e-6);
    const Motion back = r.to_model(vm.motion);
    int joint = -1;
    EXPECT_LT(max_angle_deg(back, sample(), &joint), 1e-3) << sample().skeleton.names[std::max(joint, 0)];
    EXPECT_LT(max_root_diff(back, sample()), 1e-5);
    // Nothing solved: back on the user's rig is the identity on every joint.
    const Motion again = r.to_user(back, vm.motion);
    EXPECT_LT(max_angle_deg(again, vm.motion), 1e-5);
    EXPECT_LT(max_root_diff(again, vm.motion), 1e-5 * v.length_unit);
  }
}

// Rigs without hands (ReActIdle's: the forearm is the arm's last joint, the
// wrist its End Site) map shoulder, upper arm and forearm to the model's, not
// one bone further down the arm, and retarget with the forearm continuing the
// upper arm at rest.
TEST(Retarget, ArmsWithoutHandsMapAndRetarget) {
  const Motion& full = sample();
  std::vector<int> kept;
  for (int j = 0; j < full.num_joints(); ++j)
    if (full.skeleton.names[j].rfind("Hand_", 0) != 0) kept.push_back(j);
  Skeleton s;
  std::vector<int> index(full.num_joints(), -1);
  for (int j : kept) {
    index[j] = static_cast<int>(s.names.size());
    s.names.push_back(full.skeleton.names[j]);
    s.parents.push_back(full.skeleton.parents[j] < 0 ? -1 : index[full.skeleton.parents[j]]);
    s.offsets.push_back(full.skeleton.offsets[j]);
  }
  s.validate();
  Motion handless = Motion::identity(s, full.num_frames(), full.fps);
  for (int f = 0; f < full.num_frames(); ++f) {
    handless.root_positions[f] = full.root_positions[f];
    for (int j : kept) handless.rotation(f, index[j]) = full.rotation(f, j);
  }
  const RigParts parts = find_rig_parts(s);
  EXPECT_TRUE(parts.missing().empty());
  for (int side = 0; side < 2; ++side) {
    const char* suffix = side == 0 ? "_L" : "_R";
    EXPECT_EQ(s.names[parts.arms[side].upper], std::string("UpperArm") + suffix);
    EXPECT_EQ(s.names[parts.arms[side].fore], std::string("LowerArm") + suffix);
    EXPECT_EQ(parts.arms[side].hand, -1);
    EXPECT_TRUE(parts.arms[side].hand_is_end);
  }
  RigMap map = map_rig(s, full.skeleton);
  EXPECT_EQ(map.user_of_model[full.skeleton.find("LowerArm_L")], s.find("LowerArm_L"));
  EXPECT_EQ(map.user_of_model[full.skeleton.find("Hand_L")], -1);
  const Retargeter r(s, full.skeleton, map, estimate_anatomy(handless, map.user_parts), sample_anatomy());
  const Motion on_model = r.to_model(handless);
  for (const char* j : {"UpperArm_L", "LowerArm_L", "UpperArm_R", "LowerArm_R", "Shoulder_L", "Chest"}) {
    const int m = full.skeleton.find(j);
    double worst = 0;
    for (int f = 0; f < full.num_frames(); ++f)
      worst = std::max(worst, geodesic_angle(on_model.rotation(f, m).normalized(), full.rotation(f, m).normalized()));
    EXPECT_LT(worst * 180 / M_PI, 1.0) << j;
  }
}

// A rig whose rest pose is a T or A pose gives every part's frame from that
// pose: a few frames then give the anatomy the whole motion gives,
// where the cues of the motion alone do not. Random local frames and the
// sample's own rest (every bone along local X) are not recognised.
TEST(Retarget, RestPoseFramesOfTAndAPoseRigsAreTheWholeMotionsAnatomy) {
  int recognised = 0;
  for (const bench::RigVariant& v0 : bench::standard_rig_variants()) {
    bench::RigVariant v = v0;
    v.fps = 0;
    SCOPED_TRACE(v.name);
    const bench::VariantMotion vm = bench::make_variant(sample(), sample_anatomy(), v);
    const RigMap map = map_rig(vm.motion.skeleton, sample().skeleton);
    const RigAnatomy whole = estimate_anatomy(vm.motion, map.user_parts);
    const std::vector<int> few = {0, 1, 2};
    RigAnatomy a = estimate_anatomy(vm.motion, map.user_parts, few);
    const RigAnatomy motion_only = a;
    const bool taken = take_rest_pose_frames(vm.motion.skeleton, map.user_parts, &a);
    EXPECT_EQ(taken, v.rest == "tpose" || v.rest == "apose");
    if (!taken) continue;
    ++recognised;
    const RigParts& p = map.user_parts;
    double worst = 0, worst_motion_only = 0;
    for (int j : {p.hips, p.chest, p.head, p.arms[0].upper, p.arms[0].fore, p.arms[1].hand, p.arms[1].shoulder,
                  p.legs[0].thigh, p.legs[1].shin}) {
      worst = std::max(worst, geodesic_angle(a.frames[j], whole.frames[j]) * 180 / M_PI);
      worst_motion_only = std::max(worst_motion_only, geodesic_angle(motion_only.frames[j], whole.frames[j]) * 180 / M_PI);
    }
    if (v.rest_jitter_degrees > 0) {  // a rough pose: off by about its jitter, not more
      EXPECT_LT(worst, 2 * v.rest_jitter_degrees) << "degrees";
      continue;
    }
    EXPECT_LT(worst, 0.01) << "degrees";
    EXPECT_GT(worst_motion_only, 1.0) << "the premise: three frames of motion alone are off";
    for (int s = 0; s < 2; ++s)
      EXPECT_LT(geodesic_angle(a.toe_frames[p.legs[s].foot], whole.toe_frames[p.legs[s].foot]) * 180 / M_PI, 0.01);
  }
  EXPECT_GE(recognised, 4);
  RigAnatomy native = sample_anatomy();
  EXPECT_FALSE(take_rest_pose_frames(sample().skeleton, find_rig_parts(sample().skeleton), &native));
}

// A T-pose rig whose rest pose has the elbows' convention of its motion (the
// synthetic rigs are built on the training rig's anatomy): bent elbows measure
// the same hinge up to the noise of a few frames, and the rest pose's exact
// frames are kept (user_rig_anatomy, kElbowConventionDegrees).
TEST(Retarget, BentElbowsKeepARestPoseThatAgreesWithThem) {
  const bench::VariantMotion vm = bench::make_variant(sample(), sample_anatomy(), bench::rig_variant("mixamo"));
  const RigMap map = map_rig(vm.motion.skeleton, sample().skeleton);
  const std::vector<int> few = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10};
  const std::array<double, 2> bend = mean_elbow_bend(vm.motion, map.user_parts, few);
  ASSERT_GE(std::min(bend[0], bend[1]), 0.15) << "the premise: the elbows bend";
  RigAnatomy rest = estimate_anatomy(vm.motion, map.user_parts, few);
  ASSERT_TRUE(take_rest_pose_frames(vm.motion.skeleton, map.user_parts, &rest));
  const RigAnatomy a = user_rig_anatomy(vm.motion, map.user_parts, few);
  for (int s = 0; s < 2; ++s) {
    const int fore = map.user_parts.arms[s].fore;
    EXPECT_LT(geodesic_angle(a.frames[fore], rest.frames[fore]), 1e-9) << "arm " << s;
  }
}

// The rest pose is read whichever axis it stands along and wherever it faces:
// the whole rig turned turns every frame read from it with it. An arm raised
// out of the pose is not read.
TEST(Retarget, RestPoseFramesTurnWithTheRig) {
  const bench::VariantMotion vm = bench::make_variant(sample(), sample_anatomy(), bench::rig_variant("mixamo"));
  const RigMap map = map_rig(vm.motion.skeleton, sample().skeleton);
  RigAnatomy upright = estimate_anatomy(vm.motion, map.user_parts);
  ASSERT_TRUE(take_rest_pose_frames(vm.motion.skeleton, map.user_parts, &upright));
  // Z up and facing +X.
  const Eigen::Quaterniond turn = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ())) *
                                  Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()));
  Skeleton turned = vm.motion.skeleton;
  for (Eigen::Vector3d& o : turned.offsets) o = turn * o;
  RigAnatomy a = upright;
  ASSERT_TRUE(take_rest_pose_frames(turned, map.user_parts, &a));
  for (const auto& [part, j] : map.user_parts.list())
    EXPECT_LT(geodesic_angle(a.frames[j], turn * upright.frames[j]) * 180 / M_PI, 1e-6) << part;
  Skeleton raised = vm.motion.skeleton;
  const int fore = map.user_parts.arms[0].fore;
  raised.offsets[fore] = Eigen::AngleAxisd(M_PI / 3, Eigen::Vector3d::UnitZ()) * raised.offsets[fore];
  EXPECT_FALSE(take_rest_pose_frames(raised, map.user_parts, &a));
}

TEST(Retarget, AnatomyJsonRoundTrip) {
  const std::string text = sample_anatomy().to_json(sample().skeleton);
  const RigAnatomy a = RigAnatomy::from_json(text, sample().skeleton, "x.json");
  ASSERT_EQ(a.frames.size(), sample_anatomy().frames.size());
  for (size_t j = 0; j < a.frames.size(); ++j) EXPECT_LT(geodesic_angle(a.frames[j], sample_anatomy().frames[j]), 1e-9);
  EXPECT_THROW(RigAnatomy::from_json("{}", sample().skeleton, "x.json"), InputError);
  EXPECT_THROW(RigAnatomy::from_json("nope", sample().skeleton, "x.json"), InputError);
}

// The sample walk with the left knee turned about one fixed axis only, as the
// training data's knees do (a hinge).
Motion hinge_knee_walk(int* knee, Eigen::Vector3d* hinge) {
  Motion m = sample();
  *knee = m.skeleton.find("LowerLeg_L");
  *hinge = Eigen::Vector3d(0.2, 1.0, -0.1).normalized();
  for (int f = 0; f < m.num_frames(); ++f)
    m.rotation(f, *knee) = Eigen::Quaterniond(Eigen::AngleAxisd(0.3 + 0.5 * std::sin(0.2 * f), *hinge));
  return m;
}

// The anatomy of `m` with its locked axes, as `motionfield-train rig` measures it.
RigAnatomy anatomy_with_locked_axes(const Motion& m) {
  RigAnatomy a = estimate_anatomy(m, find_rig_parts(m.skeleton));
  measure_locked_axes(m, 0.6, &a);
  return a;
}

TEST(Retarget, LockedAxesOfAHingeAreMeasuredAndRemoved) {
  int knee = -1;
  Eigen::Vector3d hinge;
  const Motion m = hinge_knee_walk(&knee, &hinge);
  RigAnatomy a = anatomy_with_locked_axes(m);
  ASSERT_EQ(a.locked_axes.size(), static_cast<size_t>(m.num_joints()));
  ASSERT_EQ(a.locked_axes[knee].size(), 2u);
  for (const Eigen::Vector3d& axis : a.locked_axes[knee]) EXPECT_LT(std::abs(axis.dot(hinge)), 1e-6);
  int free = 0;  // a joint the walk turns every way
  while (free < m.num_joints() && !a.locked_axes[free].empty()) ++free;
  ASSERT_LT(free, m.num_joints());

  // A rotation off the hinge comes back onto it; one on it is unchanged.
  const Eigen::Quaterniond on(Eigen::AngleAxisd(0.7, hinge));
  const Eigen::Quaterniond off = on * Eigen::Quaterniond(Eigen::AngleAxisd(0.05, a.locked_axes[knee][0]));
  EXPECT_GT(geodesic_angle(off, on), 0.04);
  EXPECT_LT(geodesic_angle(without_locked_rotation(a, knee, off), on), 0.002);
  EXPECT_LT(geodesic_angle(without_locked_rotation(a, knee, on), on), 1e-9);
  EXPECT_EQ(without_locked_rotation(a, free, off).coeffs(), off.coeffs());

  const RigAnatomy back = RigAnatomy::from_json(a.to_json(m.skeleton), m.skeleton, "x.json");
  ASSERT_EQ(back.locked_axes[knee].size(), 2u);
  for (int k = 0; k < 2; ++k) EXPECT_LT((back.locked_axes[knee][k] - a.locked_axes[knee][k]).norm(), 1e-12);
  for (int j = 0; j < m.num_joints(); ++j) EXPECT_EQ(back.locked_axes[j].size(), a.locked_axes[j].size());
  std::string bad = a.to_json(m.skeleton);
  bad.replace(bad.find("\"locked_axes\""), 13, "\"locked_axes\": [[0, 0, 0]], \"x\"");
  EXPECT_THROW(RigAnatomy::from_json(bad, m.skeleton, "x.json"), InputError);
}

// A user's anatomy measured on a few frames is a little off (here the thigh's
// frame turned 2 degrees about the bone): without the model's locked axes the
// knee would leave its hinge on the model's side. With them it stays on it,
// and the joints below keep their world orientation.
TEST(Retarget, MotionOntoTheModelKeepsTheModelsHinges) {
  int knee = -1;
  Eigen::Vector3d hinge;
  const Motion m = hinge_knee_walk(&knee, &hinge);
  RigAnatomy model = anatomy_with_locked_axes(m);
  for (int j = 0; j < m.num_joints(); ++j)
    if (j != knee) model.locked_axes[j].clear();  // the hand-made walk holds other joints still too
  const bench::VariantMotion vm = bench::make_variant(m, model, bench::rig_variant("mixamo"));
  const RigMap map = map_rig(vm.motion.skeleton, m.skeleton);
  RigAnatomy user = estimate_anatomy(vm.motion, map.user_parts);
  const int user_thigh = vm.motion.skeleton.find("mixamorig:LeftUpLeg");
  ASSERT_GE(user_thigh, 0);
  user.frames[user_thigh] = user.frames[user_thigh] * Eigen::Quaterniond(Eigen::AngleAxisd(2.0 * M_PI / 180, Eigen::Vector3d::UnitX()));
  RigAnatomy unlocked = model;
  unlocked.locked_axes.clear();
  const Motion kept = Retargeter(vm.motion.skeleton, m.skeleton, map, user, model).to_model(vm.motion);
  const Motion loose = Retargeter(vm.motion.skeleton, m.skeleton, map, user, unlocked).to_model(vm.motion);
  double off_hinge = 0, loose_off_hinge = 0;
  for (int f = 0; f < m.num_frames(); ++f) {
    off_hinge = std::max(off_hinge, geodesic_angle(kept.rotation(f, knee), without_locked_rotation(model, knee, kept.rotation(f, knee))));
    loose_off_hinge = std::max(loose_off_hinge, geodesic_angle(loose.rotation(f, knee), without_locked_rotation(model, knee, loose.rotation(f, knee))));
  }
  EXPECT_LT(off_hinge, 1e-9);
  EXPECT_GT(loose_off_hinge, 0.5 * M_PI / 180);  // the premise: the error leaves the hinge
  const GlobalPose gk = forward_kinematics(kept), gl = forward_kinematics(loose);
  for (const char* name : {"Foot_L", "Toes_L"}) {
    const int j = m.skeleton.find(name);
    for (int f = 0; f < m.num_frames(); ++f) EXPECT_LT(geodesic_angle(gk.rotation(f, j), gl.rotation(f, j)), 1e-6) << name;
  }
}

// A context whose prior is a tiny untrained model on the sample's rig: the
// adapter needs its skeleton, frame rate and the rig anatomy, not its weights.
TaskContext sample_rig_context() {
  TaskContext ctx;
  ctx.model = test::shared_runtime_of(NemfModel(test::tiny_nemf_config(), measure_rig(sample().skeleton, {&sample()})));
  ctx.model_anatomy = std::make_shared<const RigAnatomy>(sample_anatomy());
  return ctx;
}

double mean_angle_deg(const Motion& a, const Motion& b, const std::vector<int>& joints, const std::vector<int>& frames) {
  double sum = 0;
  for (int f : frames)
    for (int j : joints) sum += geodesic_angle(a.rotation(f, j).normalized(), b.rotation(f, j).normalized());
  return sum / (frames.size() * joints.size()) * 180 / M_PI;
}

// An oracle on the model's rig (it returns the sample, the truth) seen
// through the adapter: the user gets the truth on their rig, at their rate,
// the known frames exactly, and the joints the model lacks interpolated.
TEST(ModelRig, OracleThroughTheAdapterGivesTheTruthOnTheUsersRig) {
  const TaskContext ctx = sample_rig_context();
  for (const char* name : {"mixamo", "lafan1", "unreal", "cmu", "rigify"}) {
    SCOPED_TRACE(name);
    const bench::RigVariant v = bench::rig_variant(name);
    const bench::VariantMotion vm = bench::make_variant(sample(), sample_anatomy(), v);
    const Motion& truth = vm.motion;
    const int N = truth.num_frames();
    std::vector<int> known;  // keys every half second and the last frame
    const int step = static_cast<int>(std::lround(truth.fps / 2));
    for (int f = 0; f < N - 1; f += step) known.push_back(f);
    known.push_back(N - 1);
    int calls = 0;
    const Motion out = complete_on_model_rig(truth, known, ctx, [&](const Motion& in, const std::vector<int>& k) {
      ++calls;
      EXPECT_TRUE(in.skeleton.same_as(sample().skeleton));
      EXPECT_DOUBLE_EQ(in.fps, 30.0);
      EXPECT_EQ(in.num_frames(), sample().num_frames());
      EXPECT_GE(k.size(), 2u);
      return sample();
    });
    EXPECT_EQ(calls, 1);
    ASSERT_TRUE(out.skeleton.same_as(truth.skeleton));
    ASSERT_EQ(out.num_frames(), N);
    EXPECT_EQ(out.fps, truth.fps);
    for (int f : known)
      for (int j = 0; j < truth.num_joints(); ++j) {
        ASSERT_EQ(out.rotation(f, j).coeffs(), truth.rotation(f, j).coeffs());
        ASSERT_EQ(out.root_positions[f], truth.root_positions[f]);
      }
    const RigMap map = map_rig(truth.skeleton, sample().skeleton);
    std::vector<int> mapped, unknown;
    for (int u : map.user_of_model)
      if (u >= 0) mapped.push_back(u);
    for (int f = 0, i = 0; f < N; ++f)
      if (i < static_cast<int>(known.size()) && known[i] == f) ++i;
      else unknown.push_back(f);
    const double err = mean_angle_deg(out, truth, mapped, unknown);
    // Near exact at the model's rate (twist bones and extra spine joints are
    // placed by interpolation); other rates add the interpolation between 30 fps frames.
    EXPECT_LT(err, v.fps > 0 ? 1.5 : 0.1) << "mean rotation error of the mapped joints, degrees";
    const Motion interp = interpolate_motion(truth, known);
    EXPECT_LT(err, 0.5 * mean_angle_deg(interp, truth, mapped, unknown));
    for (int j = 0; j < truth.num_joints(); ++j) {
      if (std::find(mapped.begin(), mapped.end(), j) != mapped.end() || map.user_parts.part_of(j) != "") continue;
      if (truth.skeleton.names[j].find("Index2") == std::string::npos) continue;  // a finger: interpolated
      for (int f : unknown) EXPECT_LT(geodesic_angle(out.rotation(f, j), interp.rotation(f, j)), 1e-6);
    }
  }
}

// Real files put the floor anywhere (ReActIdle's BVH files read with their
// feet 0.73 m below zero; climbing keys stand on a structure): the learned
// methods see the motion on their training data's floor, and the result
// comes back on the user's.
TEST(ModelRig, TheModelSeesItsOwnFloorAndTheUserGetsTheirs) {
  const TaskContext ctx = sample_rig_context();
  const RigInfo& rig = ctx.model->rig();
  auto lowest_foot = [&](const Motion& m, int f) {
    const GlobalPose g = forward_kinematics(m.slice(f, f + 1));
    double low = 1e9;
    for (int k = 0; k < rig.num_feet(); ++k) low = std::min(low, g.position(0, rig.foot_joints[k]).y() - rig.foot_heights[k]);
    return low;
  };
  for (const char* name : {"rigify", "cmu"}) {
    SCOPED_TRACE(name);
    bench::VariantMotion vm = bench::make_variant(sample(), sample_anatomy(), bench::rig_variant(name));
    Motion truth = vm.motion;
    for (Eigen::Vector3d& p : truth.root_positions) p.y() -= 0.73;
    const int N = truth.num_frames();
    std::vector<int> known;
    const int step = static_cast<int>(std::lround(truth.fps / 2));
    for (int f = 0; f < N - 1; f += step) known.push_back(f);
    known.push_back(N - 1);
    const Motion out = complete_on_model_rig(truth, known, ctx, [&](const Motion& in, const std::vector<int>& k) {
      for (int f : k) EXPECT_NEAR(lowest_foot(in, f), lowest_foot(sample(), f), 0.03) << "frame " << f;
      return sample();
    });
    std::vector<int> unknown;
    for (int f = 0, i = 0; f < N; ++f)
      if (i < static_cast<int>(known.size()) && known[i] == f) ++i;
      else unknown.push_back(f);
    double err = 0;
    for (int f : unknown) err += std::abs(out.root_positions[f].y() - truth.root_positions[f].y());
    EXPECT_LT(err / unknown.size(), 0.02) << "mean root height error, metres";
  }
}

// The ground under the keys: the lowest foot at each key, a key in the air not
// lifting it, linear between keys.
TEST(GroundLevel, LowestFootUnderTheKeysWithAJumpInBetween) {
  const RigInfo rig = measure_rig(sample().skeleton, {&sample()});
  Motion m = sample();
  const int N = m.num_frames();
  // A step up of 0.4 m from frame 30 on; frame 15 lifted 0.5 m (a jump).
  ASSERT_GE(N, 61);
  for (int f = 30; f < N; ++f) m.root_positions[f].y() += 0.4;
  m.root_positions[15].y() += 0.5;
  const std::vector<int> known{0, 15, 45, N - 1};
  const std::vector<double> near = ground_heights(m, known, rig, 40);
  ASSERT_EQ(static_cast<int>(near.size()), N);
  EXPECT_NEAR(near[0], 0.0, 0.03);
  EXPECT_NEAR(near[15], 0.0, 0.03) << "the jump key is within 40 frames of a key on the floor";
  EXPECT_NEAR(near[45], 0.4, 0.03);
  EXPECT_NEAR(near[30], 0.5 * (near[15] + near[45]), 1e-12) << "linear between keys";
  EXPECT_NEAR(near[N - 1], 0.4, 0.03);
  const std::vector<double> alone = ground_heights(m, known, rig, 5);
  EXPECT_NEAR(alone[15], 0.5, 0.05) << "with no key on the floor near it, the jump key stands on its own feet";
  Motion shifted = m;
  shift_root_heights(&shifted, near, -1.0);
  EXPECT_NEAR(shifted.root_positions[N - 1].y(), sample().root_positions[N - 1].y(), 0.03);
}

// Every file of the foreign capture (real CMU and ReActIdle files on five rig
// conventions) maps onto the shipped model's rig, by names where they have them.
TEST(ModelRig, EveryFileOfTheForeignCaptureMapsOntoTheModel) {
  const std::string archive = default_foreign_archive();
  if (!std::filesystem::exists(archive)) GTEST_SKIP() << archive << " is not there";
  const std::string model_path = std::string(MF_SOURCE_DIR) + "/models/motionfield-prior.mfm";
  TaskContext ctx;
  auto model = std::make_shared<const runtime::NemfRuntime>(runtime::NemfRuntime::load(model_path));
  ctx.model = model;
  ctx.model_anatomy = load_rig_anatomy_next_to(model_path, model->rig().skeleton);
  ASSERT_TRUE(ctx.model_anatomy);
  const bench::ForeignData data = bench::load_foreign_data(archive, default_cache_dir(), 30.0, false);
  EXPECT_GE(data.train.size() + data.validation.size(), 62u);
  for (const auto* split : {&data.train, &data.validation})
    for (const bench::ForeignClip& c : *split) {
      SCOPED_TRACE(c.clip.name);
      RigMap map;
      ASSERT_NO_THROW(map = model_rig_map(c.clip.motion.skeleton, ctx));
      const Skeleton& m = model->rig().skeleton;
      for (const char* j : {"Hips", "Chest", "Head", "UpperArm_L", "LowerArm_R", "UpperLeg_L", "Foot_R"})
        EXPECT_GE(map.user_of_model[m.find(j)], 0) << j;
      EXPECT_NO_THROW(model_retargeter(c.clip.motion, {}, ctx));
    }
}

// The training data's elbows turn about two axes only: the (1, 0) element of
// their local rotation matrix stays 0 (standard deviation 0.001 in the
// transformer's statistics). Real CMU files have a T-pose rest whose
// palms-down convention does not hold; with the elbows' hinge taken from that
// rest, retargeted elbows had that element near -1.
TEST(ModelRig, RealElbowsRetargetWithinTheTrainingDatasAxes) {
  const std::string archive = default_foreign_archive();
  if (!std::filesystem::exists(archive)) GTEST_SKIP() << archive << " is not there";
  const std::string model_path = std::string(MF_SOURCE_DIR) + "/models/motionfield-prior.mfm";
  TaskContext ctx;
  auto model = std::make_shared<const runtime::NemfRuntime>(runtime::NemfRuntime::load(model_path));
  ctx.model = model;
  ctx.model_anatomy = load_rig_anatomy_next_to(model_path, model->rig().skeleton);
  const bench::ForeignData data = bench::load_foreign_data(archive, default_cache_dir(), 30.0, false);
  int checked = 0;
  for (const bench::ForeignClip& c : data.validation) {
    if (c.convention != "cmu-cgspeed" && c.convention != "cmu-daz") continue;
    SCOPED_TRACE(c.clip.name);
    const Motion on_model = model_retargeter(c.clip.motion, {}, ctx).to_model(c.clip.motion);
    for (const char* elbow : {"LowerArm_L", "LowerArm_R"}) {
      const int j = model->rig().skeleton.find(elbow);
      double sum = 0;
      for (int f = 0; f < on_model.num_frames(); ++f)
        sum += std::abs(on_model.rotation(f, j).normalized().toRotationMatrix()(1, 0));
      EXPECT_LT(sum / on_model.num_frames(), 0.1) << elbow;
    }
    ++checked;
  }
  EXPECT_GE(checked, 10);
}

TEST(ModelRig, NativeRigAtOtherRatesIsResampledAroundTheModel) {
  const TaskContext ctx = sample_rig_context();
  bench::RigVariant v = bench::rig_variant("mixamo");
  v.convention = "native", v.rest = "native", v.fingers = false, v.extra_spine = false, v.length_unit = 0.01;
  v.fps = 60;
  const Motion at60 = bench::make_variant(sample(), sample_anatomy(), v).motion;
  ASSERT_TRUE(at60.skeleton.same_as(sample().skeleton, 1e-6));
  EXPECT_TRUE(needs_model_rig(at60, ctx));
  const std::vector<int> known{0, 7, 30, 61, 90, at60.num_frames() - 1};  // 7 and 61 fall between 30 fps frames
  const Motion out = complete_on_model_rig(at60, known, ctx, [&](const Motion& in, const std::vector<int>& k) {
    EXPECT_EQ(in.num_frames(), sample().num_frames());
    EXPECT_TRUE(std::is_sorted(k.begin(), k.end()));
    return sample();
  });
  EXPECT_EQ(out.num_frames(), at60.num_frames());
  for (int f : known) EXPECT_EQ(out.rotation(f, 3).coeffs(), at60.rotation(f, 3).coeffs());
  std::vector<int> all(at60.num_joints());
  for (int j = 0; j < at60.num_joints(); ++j) all[j] = j;
  std::vector<int> frames;
  for (int f = 0; f < at60.num_frames(); ++f) frames.push_back(f);
  EXPECT_LT(mean_angle_deg(out, at60, all, frames), 1.0);
}

// A frame rate so low that the motion's span at the model's rate would exceed
// kMaxResampledFrames (or overflow a double) is refused before any solve.
TEST(ModelRig, RatesSpanningTooManyModelFramesAreClearErrors) {
  const TaskContext ctx = sample_rig_context();
  for (double fps : {1e-6, 1e-300, std::numeric_limits<double>::denorm_min()}) {
    SCOPED_TRACE(fps);
    Motion slow = sample();
    slow.fps = fps;
    bool called = false;
    try {
      complete_on_model_rig(slow, {0, 30, slow.num_frames() - 1}, ctx, [&](const Motion& m, const std::vector<int>&) {
        called = true;
        return m;
      });
      FAIL() << "no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("frames at the model's 30 fps"), std::string::npos) << e.what();
    }
    MotionConstraints keys;
    keys.keys.resize(2);  // whole poses (every joint, the root position) at the ends
    keys.keys[1].frame = slow.num_frames() - 1;
    std::vector<std::string> warnings;
    EXPECT_THROW(complete_constrained_on_model_rig(
                     slow, keys, ctx,
                     [&](const Motion& m, const MotionConstraints&) {
                       called = true;
                       return m;
                     },
                     &warnings),
                 InputError);
    EXPECT_FALSE(called);
  }
}

TEST(ModelRig, UnmappableRigAndMissingAnatomyAreClearErrors) {
  TaskContext ctx = sample_rig_context();
  const Motion other = bench::make_variant(sample(), sample_anatomy(), bench::rig_variant("mixamo")).motion;
  ctx.model_anatomy = nullptr;
  try {
    complete_on_model_rig(other, {0, 30, 60}, ctx, [](const Motion& m, const std::vector<int>&) { return m; });
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("motionfield-rig.json"), std::string::npos) << e.what();
  }
  ctx = sample_rig_context();
  ctx.rig_map = R"({"mixamorig:LeftHand": null})";
  EXPECT_THROW(
      complete_on_model_rig(other, {0, 30, 60}, ctx, [](const Motion& m, const std::vector<int>&) { return m; }),
      InputError);
}

// The training rig (whose joint frames are not world-aligned) mirrors: every
// joint lands where its counterpart's reflection was, the twists keep the
// mean local rotations (no bone flipped half a turn), and mirroring twice
// gives the motion back.
TEST(Mirror, MotionIsItsCounterpartsReflection) {
  const Motion& m = sample();
  const MirrorMap map = mirror_map(m.skeleton, mean_local_rotations({&m}));
  const Skeleton& s = m.skeleton;
  EXPECT_EQ(s.names[map.counterpart[s.find("UpperArm_L")]], "UpperArm_R");
  EXPECT_EQ(s.names[map.counterpart[s.find("Toes_R")]], "Toes_L");
  EXPECT_EQ(map.counterpart[s.find("Head")], s.find("Head"));
  EXPECT_LT(map.max_asymmetry, 1e-6);
  const Motion mirrored = mirror_motion(m, map);
  const Eigen::Matrix3d M = Eigen::Vector3d(-1, 1, 1).asDiagonal();
  const GlobalPose a = forward_kinematics(m), b = forward_kinematics(mirrored);
  double worst = 0.0;
  for (int f = 0; f < m.num_frames(); ++f)
    for (int j = 0; j < m.num_joints(); ++j)
      worst = std::max(worst, (b.position(f, j) - M * a.position(f, map.counterpart[j])).norm());
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(max_angle_deg(m, mirrored), 1.0);  // not the identity
  const std::vector<Eigen::Quaterniond> before = mean_local_rotations({&m}), after = mean_local_rotations({&mirrored});
  for (int j = 1; j < m.num_joints(); ++j)
    EXPECT_LT(geodesic_angle(before[j], after[j]) * 180 / M_PI, 45.0) << s.names[j];
  const Motion twice = mirror_motion(mirrored, map);
  EXPECT_LT(max_angle_deg(m, twice), 1e-6);
  EXPECT_LT(max_root_diff(m, twice), 1e-12);
}

TEST(Mirror, RigsThatCannotBeMirroredAreClearErrors) {
  Skeleton s = sample().skeleton;
  s.names[s.find("Hand_R")] = "Palm_R";  // Hand_L has no counterpart now
  const std::vector<Eigen::Quaterniond> means = mean_local_rotations({&sample()});
  try {
    mirror_map(s, means);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'Hand_L' has no right counterpart"), std::string::npos) << e.what();
  }
  Skeleton lopsided = sample().skeleton;
  lopsided.offsets[lopsided.find("LowerLeg_L")] *= 1.5;
  try {
    mirror_map(lopsided, means);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("children of 'UpperLeg_L' (LowerLeg_L) are not mirror images"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace mf
