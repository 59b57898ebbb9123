#include "bench/synthetic_rigs.h"

#include <cmath>
#include <functional>
#include <map>
#include <random>

#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "tasks/constraints/interpolation_fill.h"

namespace mf::bench {
namespace {

using Eigen::Quaterniond;
using Eigen::Vector3d;

// Names of the model rig's joints (and of the extra joints, keyed "+...") in
// one convention. %s in a sided entry is replaced by the side's spelling.
struct Convention {
  std::map<std::string, std::string> names;
};

std::string sided(const std::string& pattern, const std::string& side) {
  std::string s = pattern;
  const size_t at = s.find("%s");
  if (at != std::string::npos) s.replace(at, 2, side);
  return s;
}

std::map<std::string, std::string> convention_names(const std::string& convention) {
  // model name -> pattern; sides: {left, right} spellings per convention.
  struct Table {
    std::vector<std::pair<std::string, std::string>> center;
    std::vector<std::pair<std::string, std::string>> limbs;  // keys without the _L/_R suffix
    std::string left, right;
  };
  Table t;
  if (convention == "mixamo" || convention == "mixamo-bare" || convention == "cmu" || convention == "lafan1") {
    const bool cmu = convention == "cmu";
    t.center = {{"Hips", "Hips"},
                {"Spine", cmu ? "LowerBack" : "Spine"},
                {"+spine", cmu ? "Spine" : "Spine1"},
                {"Chest", cmu ? "Spine1" : "Spine2"},
                {"Neck", "Neck"},
                {"Head", "Head"},
                {"+root", "Root"}};
    t.limbs = {{"Shoulder", "%sShoulder"},      {"UpperArm", "%sArm"},          {"LowerArm", "%sForeArm"},
               {"Hand", "%sHand"},              {"UpperLeg", "%sUpLeg"},        {"LowerLeg", "%sLeg"},
               {"Foot", "%sFoot"},              {"Toes", convention == "lafan1" ? "%sToe" : "%sToeBase"},
               {"+finger1", "%sHandIndex1"},    {"+finger2", "%sHandIndex2"},   {"+thumb", "%sHandThumb1"},
               {"+twist", "%sForeArmTwist"},    {"+helper", "%sUpLegRoll"}};
    t.left = "Left", t.right = "Right";
  } else if (convention == "unreal") {
    t.center = {{"Hips", "pelvis"}, {"Spine", "spine_01"}, {"+spine", "spine_02"}, {"Chest", "spine_03"},
                {"Neck", "neck_01"}, {"Head", "head"},      {"+root", "root"}};
    t.limbs = {{"Shoulder", "clavicle_%s"},  {"UpperArm", "upperarm_%s"},      {"LowerArm", "lowerarm_%s"},
               {"Hand", "hand_%s"},          {"UpperLeg", "thigh_%s"},         {"LowerLeg", "calf_%s"},
               {"Foot", "foot_%s"},          {"Toes", "ball_%s"},              {"+finger1", "index_01_%s"},
               {"+finger2", "index_02_%s"},  {"+thumb", "thumb_01_%s"},        {"+twist", "lowerarm_twist_01_%s"},
               {"+helper", "thigh_twist_01_%s"}};
    t.left = "l", t.right = "r";
  } else if (convention == "rigify") {
    t.center = {{"Hips", "DEF-spine"},    {"Spine", "DEF-spine.001"}, {"+spine", "DEF-spine.002"},
                {"Chest", "DEF-spine.003"}, {"Neck", "DEF-spine.004"}, {"Head", "DEF-spine.006"},
                {"+root", "root"}};
    t.limbs = {{"Shoulder", "DEF-shoulder.%s"}, {"UpperArm", "DEF-upper_arm.%s"}, {"LowerArm", "DEF-forearm.%s"},
               {"Hand", "DEF-hand.%s"},         {"UpperLeg", "DEF-thigh.%s"},     {"LowerLeg", "DEF-shin.%s"},
               {"Foot", "DEF-foot.%s"},         {"Toes", "DEF-toe.%s"},           {"+finger1", "DEF-f_index.01.%s"},
               {"+finger2", "DEF-f_index.02.%s"}, {"+thumb", "DEF-thumb.01.%s"},  {"+twist", "DEF-forearm_twist.%s"},
               {"+helper", "MCH-knee_helper.%s"}};
    t.left = "L", t.right = "R";
  } else if (convention == "smpl") {
    t.center = {{"Hips", "Pelvis"}, {"Spine", "Spine1"}, {"+spine", "Spine2"}, {"Chest", "Spine3"},
                {"Neck", "Neck"},   {"Head", "Head"},     {"+root", "Root"}};
    t.limbs = {{"Shoulder", "%s_Collar"}, {"UpperArm", "%s_Shoulder"}, {"LowerArm", "%s_Elbow"},
               {"Hand", "%s_Wrist"},      {"UpperLeg", "%s_Hip"},      {"LowerLeg", "%s_Knee"},
               {"Foot", "%s_Ankle"},      {"Toes", "%s_Foot"},         {"+finger1", "%s_Hand"},
               {"+finger2", "%s_Hand_Index2"}, {"+thumb", "%s_Thumb1"}, {"+twist", "%s_ElbowTwist"},
               {"+helper", "%s_HipHelper"}};
    t.left = "L", t.right = "R";
  } else if (convention == "native") {
    t.center = {{"Hips", "Hips"}, {"Spine", "Spine"}, {"+spine", "Spine1"}, {"Chest", "Chest"},
                {"Neck", "Neck"}, {"Head", "Head"},   {"+root", "joint_Root"}};
    t.limbs = {{"Shoulder", "Shoulder_%s"}, {"UpperArm", "UpperArm_%s"}, {"LowerArm", "LowerArm_%s"},
               {"Hand", "Hand_%s"},         {"UpperLeg", "UpperLeg_%s"}, {"LowerLeg", "LowerLeg_%s"},
               {"Foot", "Foot_%s"},         {"Toes", "Toes_%s"},         {"+finger1", "Index1_%s"},
               {"+finger2", "Index2_%s"},   {"+thumb", "Thumb1_%s"},     {"+twist", "LowerArmTwist_%s"},
               {"+helper", "UpperLegRoll_%s"}};
    t.left = "L", t.right = "R";
  } else {
    throw InputError("unknown rig naming convention '" + convention + "'");
  }
  std::map<std::string, std::string> out;
  const std::string prefix = convention == "mixamo" ? "mixamorig:" : "";
  for (const auto& [k, v] : t.center) out[k] = prefix + v;
  for (const auto& [k, v] : t.limbs) {
    out[k + "_L"] = prefix + sided(v, t.left);
    out[k + "_R"] = prefix + sided(v, t.right);
  }
  return out;
}

struct Node {
  std::string key;  // model name or "+extra_L"
  int parent;
  Vector3d offset;
  std::vector<Quaterniond> rot;
};

Quaterniond random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  return q.normalized();
}

}  // namespace

std::vector<RigVariant> standard_rig_variants() {
  std::vector<RigVariant> v;
  RigVariant m;
  m.name = "mixamo", m.convention = "mixamo", m.rest = "tpose", m.length_unit = 1.0, m.fingers = true;
  m.extra_spine = true, m.channel_order = "XYZ";
  v.push_back(m);
  RigVariant c;
  c.name = "cmu", c.convention = "cmu", c.rest = "apose", c.length_unit = 0.0254, c.channel_order = "ZYX";
  c.fps = 120, c.fingers = true;
  v.push_back(c);
  RigVariant l;
  l.name = "lafan1", l.convention = "lafan1", l.rest = "random", l.channel_order = "YXZ", l.extra_spine = true;
  v.push_back(l);
  RigVariant u;
  u.name = "unreal", u.convention = "unreal", u.rest = "apose", u.container = true, u.twist = true, u.scale = 1.3;
  u.extra_spine = true, u.channel_order = "XZY";
  v.push_back(u);
  RigVariant r;
  r.name = "rigify", r.convention = "rigify", r.rest = "tpose", r.length_unit = 1.0, r.fps = 24, r.scale = 0.7;
  r.helper = true, r.extra_spine = true;
  v.push_back(r);
  RigVariant s;
  s.name = "smpl", s.convention = "smpl", s.rest = "tpose", s.length_unit = 1.0, s.fingers = true;
  s.extra_spine = true, s.fps = 60;
  v.push_back(s);
  RigVariant rough = m;
  rough.name = "mixamo-rough", rough.rest_jitter_degrees = 5.0;
  v.push_back(rough);
  return v;
}

RigVariant rig_variant(const std::string& name) {
  std::string names;
  for (const RigVariant& v : standard_rig_variants()) {
    if (v.name == name) return v;
    names += (names.empty() ? "" : ", ") + v.name;
  }
  throw InputError("unknown rig '" + name + "' (available: " + names + ")");
}

VariantMotion make_variant(const Motion& motion, const RigAnatomy& anatomy, const RigVariant& v) {
  const Skeleton& s = motion.skeleton;
  const int J = s.num_joints(), F = motion.num_frames();
  // New local frames: Q_j, the world rotation of joint j in the new rest pose.
  std::vector<Quaterniond> Q(J, Quaterniond::Identity());
  if (v.rest == "tpose" || v.rest == "apose") {
    Q = reference_pose(s, find_rig_parts(s), anatomy, v.rest == "apose" ? 45.0 : 0.0);
    std::mt19937_64 rng(11);
    std::normal_distribution<double> n(0.0, 1.0);
    for (int j = 0; j < J && v.rest_jitter_degrees > 0; ++j) {
      const Vector3d axis = Vector3d(n(rng), n(rng), n(rng)).normalized();
      Q[j] = Quaterniond(Eigen::AngleAxisd(v.rest_jitter_degrees * M_PI / 180.0, axis)) * Q[j];
    }
  } else if (v.rest == "random") {
    std::mt19937_64 rng(7);
    for (int j = 0; j < J; ++j) Q[j] = random_rotation(rng);
  } else if (v.rest != "native") {
    throw InputError("unknown rest pose '" + v.rest + "'");
  }
  std::vector<Node> nodes(J);
  for (int j = 0; j < J; ++j) {
    const int p = s.parents[j];
    // New world rotations G' = G Q^-1: at the new rest (identity locals) the
    // rig stands in the pose whose world rotations are Q.
    nodes[j] = {s.names[j], p, (p < 0 ? s.offsets[j] : Vector3d(Q[p] * s.offsets[j])) * v.scale, {}};
    nodes[j].rot.resize(F);
    for (int f = 0; f < F; ++f)
      nodes[j].rot[f] = ((p < 0 ? Quaterniond::Identity() : Q[p]) * motion.rotation(f, j) * Q[j].conjugate()).normalized();
  }
  auto find = [&](const std::string& key) {
    for (size_t i = 0; i < nodes.size(); ++i)
      if (nodes[i].key == key) return static_cast<int>(i);
    throw InputError("synthetic rig: the motion has no joint '" + key + "' (expected the training data's rig)");
  };
  auto identity_rot = [&] { return std::vector<Quaterniond>(F, Quaterniond::Identity()); };
  // A joint inserted on the bone above `child`, at `fraction` of its length.
  auto insert_above = [&](const std::string& child_key, const std::string& key, double fraction) {
    const int c = find(child_key);
    Node n{key, nodes[c].parent, nodes[c].offset * fraction, identity_rot()};
    nodes[c].offset *= 1.0 - fraction;
    nodes.push_back(n);
    nodes[c].parent = static_cast<int>(nodes.size()) - 1;
  };
  auto add_leaf = [&](const std::string& parent_key, const std::string& key, const Vector3d& offset, double curl) {
    Node n{key, find(parent_key), offset, identity_rot()};
    for (int f = 0; f < F; ++f)
      n.rot[f] = Quaterniond(Eigen::AngleAxisd(curl * (0.6 + 0.4 * std::sin(2 * M_PI * f / 40.0)), Vector3d::UnitZ()));
    nodes.push_back(n);
  };
  if (v.extra_spine) insert_above("Chest", "+spine", 0.5);
  for (const char* side : {"_L", "_R"}) {
    const std::string S = side;
    if (v.twist) insert_above("Hand" + S, "+twist" + S, 0.5);
    if (v.helper) add_leaf("UpperLeg" + S, "+helper" + S, Vector3d::Zero(), 0.0);
    if (v.fingers) {
      // Along the forearm's direction, in the hand's (new) frame.
      const int hand = s.find("Hand" + S);
      const Vector3d hand_dir = Q[s.parents[hand]] * s.offsets[hand].normalized();
      add_leaf("Hand" + S, "+finger1" + S, hand_dir * 0.09 * v.scale, 0.5);
      add_leaf("+finger1" + S, "+finger2" + S, hand_dir * 0.04 * v.scale, 0.7);
      add_leaf("Hand" + S, "+thumb" + S, hand_dir * 0.03 * v.scale + Vector3d(0, 0, 0.02) * v.scale, 0.3);
    }
  }
  // Depth-first order, parents first.
  std::vector<std::vector<int>> kids(nodes.size());
  for (size_t i = 1; i < nodes.size(); ++i) kids[nodes[i].parent].push_back(static_cast<int>(i));
  std::vector<int> order;
  std::function<void(int)> visit = [&](int i) {
    order.push_back(i);
    for (int c : kids[i]) visit(c);
  };
  visit(0);
  std::vector<int> new_index(nodes.size());
  for (size_t i = 0; i < order.size(); ++i) new_index[order[i]] = static_cast<int>(i);
  const std::map<std::string, std::string> names = convention_names(v.convention);
  Motion out;
  out.fps = motion.fps;
  const int JN = static_cast<int>(order.size());
  for (int i : order) {
    out.skeleton.names.push_back(names.at(nodes[i].key));
    out.skeleton.parents.push_back(nodes[i].parent < 0 ? -1 : new_index[nodes[i].parent]);
    out.skeleton.offsets.push_back(nodes[i].offset);
  }
  out.rotations.resize(static_cast<size_t>(F) * JN);
  out.root_positions.resize(F);
  for (int f = 0; f < F; ++f) {
    for (int k = 0; k < JN; ++k) out.rotation(f, k) = nodes[order[k]].rot[f];
    out.root_positions[f] = motion.root_positions[f] * v.scale;
  }
  out.validate();
  if (v.fps > 0 && std::abs(v.fps - out.fps) > 1e-9) {
    const int frames = static_cast<int>(std::floor((F - 1) * v.fps / out.fps + 1e-6)) + 1;
    out = resample_interpolate(out, v.fps, frames);
  }

  VariantMotion result;
  result.units.length_scale = v.length_unit;
  BvhDocument layout = default_bvh_layout(out.skeleton, result.units);
  const EulerOrder order_rot = euler_order_from_string(v.channel_order);
  auto channel = [](Axis a) {
    return a == Axis::X ? BvhChannel::Xrotation : a == Axis::Y ? BvhChannel::Yrotation : BvhChannel::Zrotation;
  };
  for (size_t j = 0; j < layout.joints.size(); ++j) {
    std::vector<BvhChannel> ch;
    if (j == 0) ch = {BvhChannel::Xposition, BvhChannel::Yposition, BvhChannel::Zposition};
    for (Axis a : order_rot) ch.push_back(channel(a));
    layout.joints[j].channels = ch;
  }
  if (v.container) {
    BvhJoint root;
    root.name = names.at("+root");
    root.channels = {BvhChannel::Xposition, BvhChannel::Yposition, BvhChannel::Zposition,
                     BvhChannel::Zrotation, BvhChannel::Xrotation, BvhChannel::Yrotation};
    for (BvhJoint& b : layout.joints) ++b.parent;
    layout.joints.front().parent = 0;
    layout.joints.insert(layout.joints.begin(), root);
  }
  // Through the file format, as a user's file would be read.
  const BvhDocument doc = motion_to_bvh(out, layout, result.units);
  const BvhDocument back = parse_bvh(format_bvh(doc), v.name + ".bvh");
  result.motion = motion_from_bvh(back, result.units);
  result.layout = back;
  result.layout.values.clear();
  result.layout.num_frames = 0;
  return result;
}

}  // namespace mf::bench
