// Generates samples/walk_keyframes.bvh, motionfield's bundled sample clip: a
// hand-made two-second walk (two gait cycles at 30 fps) on a 22-joint rig with
// the joint names and hierarchy of the Bandai Namco training rig. Nothing in it
// comes from motion-capture data: the bone lengths and the poses below are
// written by hand.
//
//   usage: mf-make-sample OUT.bvh
//
// How it is built:
//   * The rest skeleton is written in world terms (centimetres, Y up, facing +Z,
//     the character's left is +X) as the vector from each joint to its parent.
//   * Each joint gets a rest frame like the training rig's: its local +X axis
//     runs along the bone to its child (-X on the right side, as in that rig),
//     local +Z points forward (up for the feet and toes). Offsets and rotations
//     are expressed in these frames: L_j = B_parent^T * A_j * B_j, where A_j is
//     the "anatomical" rotation written by hand in world-aligned axes and B_j the
//     rest frame.
//   * The gait is four keyframe poses per cycle (left heel strike, left mid
//     stance, right heel strike, right mid stance), interpolated with periodic
//     Catmull-Rom splines; the right side is the left side half a cycle later.
//   * The root height keeps the lower foot on the floor and the root's forward
//     motion keeps the supporting foot from sliding.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <exception>
#include <map>
#include <string>
#include <vector>

#include "prior/motion/bvh.h"
#include "prior/motion/motion.h"
#include "prior/motion/motion_bvh.h"

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kFps = 30.0;
constexpr int kFrames = 61;          // 2 seconds
constexpr int kCycleFrames = 30;     // one gait cycle (two steps) per second
constexpr double kCm = 0.01;         // metres per centimetre

struct RigJoint {
  const char* name;
  const char* parent;          // nullptr for Hips (the motion root)
  Eigen::Vector3d from_parent; // world rest vector from the parent, cm
};

// Rest pose: standing, arms hanging slightly away from the body. Depth-first
// order, as in the file.
const std::vector<RigJoint>& rig() {
  static const std::vector<RigJoint> joints = {
      {"Hips", nullptr, {0, 97, 0}},
      {"Spine", "Hips", {0, 10, -1}},
      {"Chest", "Spine", {0, 14, 0}},
      {"Neck", "Chest", {0, 21, -1.5}},
      {"Head", "Neck", {0, 9, 1.5}},
      {"Shoulder_L", "Chest", {3, 17, -1}},
      {"UpperArm_L", "Shoulder_L", {14, 0, -1}},
      {"LowerArm_L", "UpperArm_L", {4, -27, 0}},
      {"Hand_L", "LowerArm_L", {2, -24, 2}},
      {"Shoulder_R", "Chest", {-3, 17, -1}},
      {"UpperArm_R", "Shoulder_R", {-14, 0, -1}},
      {"LowerArm_R", "UpperArm_R", {-4, -27, 0}},
      {"Hand_R", "LowerArm_R", {-2, -24, 2}},
      {"UpperLeg_L", "Hips", {9, -6, 0}},
      {"LowerLeg_L", "UpperLeg_L", {0, -40, 1}},
      {"Foot_L", "LowerLeg_L", {0, -41, -2}},
      {"Toes_L", "Foot_L", {0, -7, 13}},
      {"UpperLeg_R", "Hips", {-9, -6, 0}},
      {"LowerLeg_R", "UpperLeg_R", {0, -40, 1}},
      {"Foot_R", "LowerLeg_R", {0, -41, -2}},
      {"Toes_R", "Foot_R", {0, -7, 13}},
  };
  return joints;
}

// End Sites of the leaves (world rest vectors, cm).
const std::map<std::string, Eigen::Vector3d>& end_sites() {
  static const std::map<std::string, Eigen::Vector3d> e = {
      {"Head", {0, 16, 1}},   {"Hand_L", {1, -9, 1}}, {"Hand_R", {-1, -9, 1}},
      {"Toes_L", {0, -1, 6}}, {"Toes_R", {0, -1, 6}},
  };
  return e;
}

bool right_side(const std::string& name) { return name.size() > 2 && name.compare(name.size() - 2, 2, "_R") == 0; }

// Rest frame of a joint: columns are its local X, Y, Z axes in world terms.
Eigen::Matrix3d rest_frame(const std::string& name, const Eigen::Vector3d& bone) {
  Eigen::Vector3d x = bone.normalized();
  if (right_side(name)) x = -x;
  const bool foot = name.rfind("Foot", 0) == 0 || name.rfind("Toes", 0) == 0;
  const Eigen::Vector3d reference = foot ? Eigen::Vector3d(0, 1, 0) : Eigen::Vector3d(0, 0, 1);
  Eigen::Vector3d z = (reference - reference.dot(x) * x).normalized();
  Eigen::Matrix3d b;
  b.col(0) = x;
  b.col(1) = z.cross(x);
  b.col(2) = z;
  return b;
}

// ------------------------------------------------------------------ the gait

// A channel keyed at phases 0, 0.25, 0.5 and 0.75 of the cycle (degrees).
using Keys = std::array<double, 4>;

// Periodic Catmull-Rom through the four keys; phase in cycles (any real).
double sample(const Keys& k, double phase) {
  double p = phase - std::floor(phase);
  const double s = p * 4.0;
  const int i = static_cast<int>(std::floor(s)) % 4;
  const double t = s - std::floor(s);
  const double p0 = k[(i + 3) % 4], p1 = k[i], p2 = k[(i + 1) % 4], p3 = k[(i + 2) % 4];
  return 0.5 * ((2 * p1) + (-p0 + p2) * t + (2 * p0 - 5 * p1 + 4 * p2 - p3) * t * t + (-p0 + 3 * p1 - 3 * p2 + p3) * t * t * t);
}

// Anatomical rotation angles (degrees) about world-aligned axes: x = flexion
// about the lateral axis (positive swings a hanging limb backward), y = about
// the vertical, z = about the forward axis.
struct JointKeys {
  Keys x{0, 0, 0, 0}, y{0, 0, 0, 0}, z{0, 0, 0, 0};
};

// Left-side and trunk keys. Phase 0: left heel strike; 0.25: left mid stance
// (right leg swinging); 0.5: right heel strike; 0.75: right mid stance.
std::map<std::string, JointKeys> gait_keys() {
  std::map<std::string, JointKeys> k;
  k["Hips"].y = {-5, 0, 5, 0};         // pelvis turns with the forward leg
  k["Hips"].z = {0, 3, 0, -3};         // drops on the swing side
  k["Spine"].x = {3, 3, 3, 3};         // slight forward lean
  k["Chest"].y = {8, 0, -8, 0};        // shoulders counter-rotate
  k["Chest"].x = {1, 2, 1, 2};
  k["Neck"].y = {-2, 0, 2, 0};
  k["Head"].x = {-4, -5, -4, -5};      // keep the gaze level
  k["UpperLeg_L"].x = {-22, -4, 13, -28};
  k["LowerLeg_L"].x = {5, 12, 30, 60};
  k["Foot_L"].x = {2, -6, 12, -20};     // negative lifts the toes
  k["Toes_L"].x = {0, 0, -25, 0};
  k["Shoulder_L"].z = {0, 1, 0, 1};
  k["UpperArm_L"].x = {18, 2, -16, 2}; // opposite to the left leg
  k["UpperArm_L"].z = {4, 4, 4, 4};    // hang slightly away from the body
  k["LowerArm_L"].x = {-12, -20, -35, -20};
  k["Hand_L"].x = {-5, -5, -8, -5};
  return k;
}

Eigen::Matrix3d anatomical_rotation(const JointKeys& k, double phase, bool mirror) {
  // Right side: the left side half a cycle later, mirrored across the sagittal
  // plane (rotations about the vertical and forward axes change sign).
  const double p = mirror ? phase + 0.5 : phase;
  const double s = mirror ? -1.0 : 1.0;
  const double x = sample(k.x, p) * kPi / 180, y = s * sample(k.y, p) * kPi / 180, z = s * sample(k.z, p) * kPi / 180;
  return (Eigen::AngleAxisd(y, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(x, Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(z, Eigen::Vector3d::UnitZ()))
      .toRotationMatrix();
}

// Rounds to 1e-4 cm so the file shows 17.028 rather than 17.0280449 and 2e-16.
Eigen::Vector3d tidy(const Eigen::Vector3d& cm) {
  return cm.unaryExpr([](double v) { return std::round(v * 1e4) / 1e4 + 0.0; });
}

std::string left_name(const std::string& name) {
  return right_side(name) ? name.substr(0, name.size() - 2) + "_L" : name;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: mf-make-sample OUT.bvh\n");
    return 2;
  }
  try {
    const auto& joints = rig();
    const int J = static_cast<int>(joints.size());
    std::map<std::string, int> index;
    for (int j = 0; j < J; ++j) index[joints[j].name] = j;

    // Rest frames: the bone to the (first) child; leaves use their End Site.
    std::vector<Eigen::Matrix3d> frame(J);
    std::vector<int> parent(J, -1);
    for (int j = 0; j < J; ++j) {
      if (joints[j].parent) parent[j] = index.at(joints[j].parent);
      Eigen::Vector3d bone = Eigen::Vector3d::Zero();
      for (int c = j + 1; c < J && bone.isZero(); ++c)
        if (joints[c].parent && joints[c].parent == std::string(joints[j].name)) bone = joints[c].from_parent;
      if (bone.isZero()) bone = end_sites().at(joints[j].name);
      frame[j] = rest_frame(joints[j].name, bone);
    }

    mf::Skeleton skeleton;
    for (int j = 0; j < J; ++j) {
      skeleton.names.push_back(joints[j].name);
      skeleton.parents.push_back(parent[j]);
      const Eigen::Matrix3d parent_frame = parent[j] < 0 ? Eigen::Matrix3d::Identity() : frame[parent[j]];
      skeleton.offsets.push_back(tidy(parent_frame.transpose() * joints[j].from_parent) * kCm);
    }

    // Anatomical (world-aligned) rotations per frame, then world FK in that
    // convention to place the root so that feet stay on the floor.
    const auto keys = gait_keys();
    mf::Motion motion = mf::Motion::identity(skeleton, kFrames, kFps);
    const std::vector<std::string> feet = {"Foot_L", "Toes_L", "Foot_R", "Toes_R"};
    std::vector<Eigen::Vector3d> rest_world(J);
    for (int j = 0; j < J; ++j) rest_world[j] = (parent[j] < 0 ? Eigen::Vector3d::Zero() : rest_world[parent[j]]) + joints[j].from_parent;

    std::vector<std::vector<Eigen::Vector3d>> rel(kFrames, std::vector<Eigen::Vector3d>(J));  // root-relative, cm
    for (int f = 0; f < kFrames; ++f) {
      const double phase = static_cast<double>(f) / kCycleFrames;
      std::vector<Eigen::Matrix3d> global(J);
      for (int j = 0; j < J; ++j) {
        const auto it = keys.find(left_name(joints[j].name));
        const Eigen::Matrix3d a = it == keys.end() ? Eigen::Matrix3d::Identity()
                                                   : anatomical_rotation(it->second, phase, right_side(joints[j].name));
        const Eigen::Matrix3d parent_frame = parent[j] < 0 ? Eigen::Matrix3d::Identity() : frame[parent[j]];
        motion.rotation(f, j) = Eigen::Quaterniond(parent_frame.transpose() * a * frame[j]).normalized();
        if (parent[j] < 0) {
          global[j] = a;
          rel[f][j] = Eigen::Vector3d::Zero();
        } else {
          global[j] = global[parent[j]] * a;
          rel[f][j] = rel[f][parent[j]] + global[parent[j]] * joints[j].from_parent;
        }
      }
    }

    // Height: the lowest foot joint at its rest height. Forward: the lower
    // ankle is the supporting foot and does not move along the walk.
    double z = -60.0;
    for (int f = 0; f < kFrames; ++f) {
      double height = -1e9;
      for (const std::string& n : feet) {
        const int j = index.at(n);
        height = std::max(height, rest_world[j].y() - rel[f][j].y());
      }
      if (f > 0) {
        const int support = rel[f - 1][index.at("Foot_L")].y() < rel[f - 1][index.at("Foot_R")].y() ? index.at("Foot_L")
                                                                                                   : index.at("Foot_R");
        z -= rel[f][support].z() - rel[f - 1][support].z();
      }
      const double sway = 1.5 * std::sin(2 * kPi * f / kCycleFrames);  // towards the supporting leg
      motion.root_positions[f] = Eigen::Vector3d(sway, height, z) * kCm;
    }

    // Layout: the training rig's container root joint_Root (6 channels) above
    // Hips (6 channels); every other joint Zrotation Xrotation Yrotation.
    using C = mf::BvhChannel;
    mf::BvhDocument layout;
    mf::BvhJoint root;
    root.name = "joint_Root";
    root.channels = {C::Xposition, C::Yposition, C::Zposition, C::Zrotation, C::Xrotation, C::Yrotation};
    layout.joints.push_back(root);
    for (int j = 0; j < J; ++j) {
      mf::BvhJoint b;
      b.name = joints[j].name;
      b.parent = parent[j] < 0 ? 0 : parent[j] + 1;
      b.offset = skeleton.offsets[j] / kCm;
      if (parent[j] < 0) {
        b.channels = {C::Xposition, C::Yposition, C::Zposition, C::Zrotation, C::Xrotation, C::Yrotation};
      } else {
        b.channels = {C::Zrotation, C::Xrotation, C::Yrotation};
      }
      const auto e = end_sites().find(joints[j].name);
      if (e != end_sites().end()) {
        b.has_end_site = true;
        b.end_site = tidy(frame[j].transpose() * e->second);
      }
      layout.joints.push_back(b);
    }
    layout.frame_time = 1.0 / kFps;

    mf::write_motion(argv[1], motion, layout);
    mf::BvhDocument check;
    const mf::Motion back = mf::read_motion(argv[1], &check);
    std::printf("wrote %s: %d joints (+ joint_Root), %d frames at %g fps, walked %.2f m\n", argv[1], back.num_joints(),
                back.num_frames(), back.fps,
                (motion.root_positions.back() - motion.root_positions.front()).norm());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mf-make-sample: %s\n", e.what());
    return 1;
  }
}
