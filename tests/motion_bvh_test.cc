// Tests of the conversion between BVH documents and mf::Motion
// (prior/motion/motion_bvh.h).
#include "prior/motion/motion_bvh.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "prior/data/dataset.h"
#include "prior/motion/rotations.h"
#include "prior/util/binary_io.h"
#include "tests/test_util.h"

namespace mf {
namespace {

using C = BvhChannel;
constexpr double kPi = 3.14159265358979323846;

Eigen::Quaterniond about(double degrees, const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(degrees * kPi / 180, axis));
}

void expect_same_pose(const Motion& a, const Motion& b, double tolerance) {
  const GlobalPose pa = forward_kinematics(a), pb = forward_kinematics(b);
  ASSERT_EQ(pa.frames, pb.frames);
  ASSERT_EQ(pa.joints, pb.joints);
  double worst_position = 0, worst_angle = 0;
  for (size_t i = 0; i < pa.positions.size(); ++i) {
    worst_position = std::max(worst_position, (pa.positions[i] - pb.positions[i]).norm());
    worst_angle = std::max(worst_angle, geodesic_angle(pa.rotations[i], pb.rotations[i]));
  }
  EXPECT_LT(worst_position, tolerance);
  EXPECT_LT(worst_angle, tolerance);
}

// Hips (6 channels, Z X Y rotation order) with a Spine in XYZ order.
const char* const kTwoJoints =
    "HIERARCHY\n"
    "ROOT Hips\n"
    "{\n"
    "  OFFSET 0 0 0\n"
    "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
    "  JOINT Spine\n"
    "  {\n"
    "    OFFSET 0 10 0\n"
    "    CHANNELS 3 Xrotation Yrotation Zrotation\n"
    "    End Site\n"
    "    {\n"
    "      OFFSET 0 5 0\n"
    "    }\n"
    "  }\n"
    "}\n"
    "MOTION\n"
    "Frames: 2\n"
    "Frame Time: 0.0333333\n"
    "100 90 -50 90 0 0 0 0 0\n"
    "0 0 0 90 90 0 0 0 90\n";

// Hand-computed: frame 0 has the root at (1, 0.9, -0.5) m turned 90 degrees
// about Z, so the Spine (0, 0.1, 0) sits at root + (-0.1, 0, 0). Frame 1: the
// root is Rz(90) Rx(90) (ZXY order), the spine turns Rz(90).
TEST(MotionBvhTest, HandComputedTwoJoints) {
  const Motion m = motion_from_bvh(parse_bvh(kTwoJoints, "two.bvh"));
  ASSERT_EQ(m.num_joints(), 2);
  ASSERT_EQ(m.num_frames(), 2);
  EXPECT_EQ(m.fps, 30.0);  // 0.0333333 snaps to 30
  EXPECT_EQ(m.skeleton.names, (std::vector<std::string>{"Hips", "Spine"}));
  EXPECT_EQ(m.skeleton.parents, (std::vector<int>{-1, 0}));
  EXPECT_LT((m.skeleton.offsets[1] - Eigen::Vector3d(0, 0.1, 0)).norm(), 1e-15);
  EXPECT_LT((m.root_positions[0] - Eigen::Vector3d(1, 0.9, -0.5)).norm(), 1e-15);
  EXPECT_LT(geodesic_angle(m.rotation(0, 0), about(90, Eigen::Vector3d::UnitZ())), 1e-15);
  EXPECT_LT(geodesic_angle(m.rotation(1, 0), about(90, Eigen::Vector3d::UnitZ()) * about(90, Eigen::Vector3d::UnitX())),
            1e-15);
  EXPECT_LT(geodesic_angle(m.rotation(1, 1), about(90, Eigen::Vector3d::UnitZ())), 1e-15);
  const GlobalPose p = forward_kinematics(m);
  EXPECT_LT((p.position(0, 1) - Eigen::Vector3d(0.9, 0.9, -0.5)).norm(), 1e-15);
  // Frame 1: Rz(90) Rx(90) (0, 0.1, 0) = Rz(90) (0, 0, 0.1) = (0, 0, 0.1).
  EXPECT_LT((p.position(1, 1) - Eigen::Vector3d(0, 0, 0.1)).norm(), 1e-15);
  for (const auto& q : m.rotations) EXPECT_NEAR(q.norm(), 1.0, 1e-15);
}

TEST(MotionBvhTest, LengthScale) {
  const Motion m = motion_from_bvh(parse_bvh(kTwoJoints, "two.bvh"), BvhUnits{1.0});
  EXPECT_LT((m.root_positions[0] - Eigen::Vector3d(100, 90, -50)).norm(), 1e-12);
  EXPECT_LT((m.skeleton.offsets[1] - Eigen::Vector3d(0, 10, 0)).norm(), 1e-12);
  EXPECT_THROW(motion_from_bvh(parse_bvh(kTwoJoints, "two.bvh"), BvhUnits{0.0}), InputError);
}

// Writes `motion` with `layout`, goes through text, and reads it back.
Motion through_text(const Motion& motion, const BvhDocument& layout, BvhDocument* written = nullptr) {
  const BvhDocument doc = motion_to_bvh(motion, layout);
  if (written) *written = doc;
  return motion_from_bvh(parse_bvh(format_bvh(doc), "roundtrip.bvh"));
}

TEST(MotionBvhTest, DefaultLayout) {
  const Skeleton s = test::small_skeleton();
  const BvhDocument layout = default_bvh_layout(s);
  ASSERT_EQ(layout.joints.size(), 7u);
  EXPECT_EQ(layout.joints[0].channels,
            (std::vector<C>{C::Xposition, C::Yposition, C::Zposition, C::Zrotation, C::Xrotation, C::Yrotation}));
  for (size_t j = 1; j < 7; ++j)
    EXPECT_EQ(layout.joints[j].channels, (std::vector<C>{C::Zrotation, C::Xrotation, C::Yrotation}));
  EXPECT_LT((layout.joints[4].offset - Eigen::Vector3d(0, -80, 0)).norm(), 1e-12);  // centimetres
  int end_sites = 0;
  for (const BvhJoint& j : layout.joints) end_sites += j.has_end_site;
  EXPECT_EQ(end_sites, 3);  // Head, Foot_L, Foot_R
  EXPECT_TRUE(layout.joints[s.find("Head")].has_end_site);

  const Motion m = test::random_motion(s, 40, 30.0, 3);
  const Motion back = through_text(m, layout);
  EXPECT_TRUE(back.skeleton.same_as(s, 1e-9));
  EXPECT_EQ(back.fps, 30.0);
  expect_same_pose(m, back, 1e-6);
}

// A skeleton whose indices are not depth-first still gets a depth-first layout,
// and joints are matched by name.
TEST(MotionBvhTest, DefaultLayoutReordersToDepthFirst) {
  Skeleton s;
  s.names = {"root", "left", "right", "left_tip", "right_tip"};
  s.parents = {-1, 0, 0, 1, 2};
  s.offsets = {{0, 0, 0}, {0.1, 0, 0}, {-0.1, 0, 0}, {0, -0.3, 0}, {0, -0.3, 0}};
  const BvhDocument layout = default_bvh_layout(s);
  ASSERT_NO_THROW(layout.validate());
  EXPECT_EQ(layout.joints[2].name, "left_tip");
  const Motion m = test::random_motion(s, 10, 24.0, 9);
  const Motion back = through_text(m, layout);
  EXPECT_EQ(back.skeleton.names, (std::vector<std::string>{"root", "left", "left_tip", "right", "right_tip"}));
  // Compare joint by joint through the names.
  const GlobalPose pa = forward_kinematics(m), pb = forward_kinematics(back);
  for (int f = 0; f < 10; ++f)
    for (int j = 0; j < 5; ++j)
      EXPECT_LT((pa.position(f, j) - pb.position(f, back.skeleton.find(s.names[j]))).norm(), 1e-6);
}

// Every joint with a different channel order, position channels on a non-root
// joint (written as its offset) and a joint with its positions before its rotations.
TEST(MotionBvhTest, MixedChannelOrdersRoundTrip) {
  const Skeleton s = test::small_skeleton();
  BvhDocument layout = default_bvh_layout(s);
  const std::vector<std::vector<C>> rotations = {
      {C::Xrotation, C::Yrotation, C::Zrotation}, {C::Xrotation, C::Zrotation, C::Yrotation},
      {C::Yrotation, C::Xrotation, C::Zrotation}, {C::Yrotation, C::Zrotation, C::Xrotation},
      {C::Zrotation, C::Xrotation, C::Yrotation}, {C::Zrotation, C::Yrotation, C::Xrotation},
      {C::Yrotation, C::Xrotation, C::Zrotation}};
  for (size_t j = 0; j < layout.joints.size(); ++j) layout.joints[j].channels = rotations[j];
  layout.joints[0].channels.insert(layout.joints[0].channels.begin(), {C::Zposition, C::Xposition, C::Yposition});
  layout.joints[3].channels.insert(layout.joints[3].channels.end(), {C::Yposition, C::Xposition, C::Zposition});

  // Large rotations, so that the middle angles pass 90 degrees and the outer ones wrap.
  Motion m = test::random_motion(s, 60, 30.0, 4);
  for (int f = 0; f < m.num_frames(); ++f)
    for (int j = 0; j < m.num_joints(); ++j)
      m.rotation(f, j) = about(2.0 * f * (j + 1), Eigen::Vector3d(1, 2, 3).normalized()) * m.rotation(f, j);
  BvhDocument written;
  const Motion back = through_text(m, layout, &written);
  expect_same_pose(m, back, 1e-6);
  EXPECT_TRUE(back.skeleton.same_as(s, 1e-9));
  // UpperLeg_L's position channels carry its offset, in centimetres.
  const int leg = written.channel_offset(3);
  EXPECT_NEAR(written.values[leg + 3], -5, 1e-9);  // Yposition
  EXPECT_NEAR(written.values[leg + 4], 10, 1e-9);  // Xposition
  // Euler curves are continuous: no channel jumps by more than 90 degrees,
  // though some wind beyond +-180.
  const int channels = written.num_channels();
  double largest = 0;
  for (int f = 1; f < written.num_frames; ++f) {
    for (int c = 0; c < channels; ++c) {
      ASSERT_LT(std::abs(written.values[f * channels + c] - written.values[(f - 1) * channels + c]), 90.0)
          << "frame " << f << " channel " << c;
      largest = std::max(largest, std::abs(written.values[f * channels + c]));
    }
  }
  EXPECT_GT(largest, 360.0);
}

// A root turning at a constant rate about Y through two full turns: the written
// Y channel keeps growing instead of wrapping at 180 degrees.
TEST(MotionBvhTest, WritesEulerAnglesContinuously) {
  const Skeleton s = test::small_skeleton();
  Motion m = Motion::identity(s, 73, 30.0);
  for (int f = 0; f < 73; ++f) m.rotation(f, 0) = about(10.0 * f, Eigen::Vector3d::UnitY());
  const BvhDocument doc = motion_to_bvh(m, default_bvh_layout(s));
  const int channels = doc.num_channels();
  for (int f = 0; f < 73; ++f) {
    EXPECT_NEAR(doc.values[f * channels + 5], 10.0 * f, 1e-9) << f;  // Yrotation
    EXPECT_NEAR(doc.values[f * channels + 3], 0.0, 1e-9) << f;       // Zrotation
  }
}

// A layout like the training data's: a container root with one child, Hips,
// carrying position channels.
BvhDocument container_layout(const Eigen::Vector3d& container_offset) {
  BvhDocument doc;
  const std::vector<C> six = {C::Xposition, C::Yposition, C::Zposition, C::Zrotation, C::Xrotation, C::Yrotation};
  const char* names[] = {"joint_Root", "Hips", "Spine", "Head", "Leg"};
  const int parents[] = {-1, 0, 1, 2, 1};
  const Eigen::Vector3d offsets[] = {container_offset, {0, 93.9, -3}, {15.7, 0, 0}, {20, 0, 0}, {0, -80, 0}};
  for (int j = 0; j < 5; ++j) {
    BvhJoint joint;
    joint.name = names[j];
    joint.parent = parents[j];
    joint.offset = offsets[j];
    joint.channels = six;
    joint.has_end_site = j == 3 || j == 4;
    doc.joints.push_back(joint);
  }
  doc.frame_time = 1.0 / 30;
  return doc;
}

TEST(MotionBvhTest, ContainerRootIsComposedIntoItsChild) {
  BvhDocument doc = container_layout({0, 0, 0});
  doc.num_frames = 2;
  doc.values.assign(2 * doc.num_channels(), 0.0);
  // Container: translated (10, 0, 5) cm and turned 90 degrees about Y in frame 1.
  // Hips at (0, 90, 0) cm, unrotated. Spine and Leg channels equal their offsets.
  for (int f = 0; f < 2; ++f) {
    double* row = doc.values.data() + f * doc.num_channels();
    row[6 + 1] = 90;
    for (int j = 2; j < 5; ++j)
      for (int k = 0; k < 3; ++k) row[6 * j + k] = doc.joints[j].offset[k];
  }
  double* row1 = doc.values.data() + doc.num_channels();
  row1[0] = 10;
  row1[2] = 5;
  row1[5] = 90;  // container Yrotation

  const Motion m = motion_from_bvh(doc);
  ASSERT_EQ(m.num_joints(), 4);
  EXPECT_EQ(m.skeleton.names[0], "Hips");
  EXPECT_EQ(m.skeleton.parents, (std::vector<int>{-1, 0, 1, 0}));
  EXPECT_LT((m.root_positions[0] - Eigen::Vector3d(0, 0.9, 0)).norm(), 1e-15);
  // (0.1, 0, 0.05) + Ry(90) (0, 0.9, 0): the hips' height does not turn.
  EXPECT_LT((m.root_positions[1] - Eigen::Vector3d(0.1, 0.9, 0.05)).norm(), 1e-15);
  EXPECT_LT(geodesic_angle(m.rotation(1, 0), about(90, Eigen::Vector3d::UnitY())), 1e-15);
  // Spine offset (15.7, 0, 0) cm turned by the container: (0, 0, -0.157) from the hips.
  const GlobalPose p = forward_kinematics(m);
  EXPECT_LT((p.position(1, 1) - Eigen::Vector3d(0.1, 0.9, 0.05 - 0.157)).norm(), 1e-15);
}

// Written with a container layout whose container has a non-zero offset, the
// container gets identity channels and its child the rest; read back, every
// global pose is the same.
TEST(MotionBvhTest, ContainerRootRoundTrip) {
  const BvhDocument layout = container_layout({12, -3, 40});
  BvhDocument with_values = layout;
  with_values.num_frames = 1;
  with_values.values.assign(layout.num_channels(), 0.0);
  for (int j = 2; j < 5; ++j)
    for (int k = 0; k < 3; ++k) with_values.values[6 * j + k] = layout.joints[j].offset[k];
  const Skeleton s = motion_from_bvh(with_values).skeleton;

  const Motion m = test::random_motion(s, 30, 30.0, 5);
  BvhDocument written;
  const Motion back = through_text(m, layout, &written);
  EXPECT_EQ(back.skeleton.names, s.names);
  expect_same_pose(m, back, 1e-6);
  const int channels = written.num_channels();
  for (int f = 0; f < written.num_frames; ++f) {
    const double* row = written.values.data() + f * channels;
    EXPECT_EQ(Eigen::Vector3d(row[0], row[1], row[2]), Eigen::Vector3d(12, -3, 40));
    EXPECT_EQ(Eigen::Vector3d(row[3], row[4], row[5]), Eigen::Vector3d::Zero());
  }
}

TEST(MotionBvhTest, RejectsMismatchedLayouts) {
  const Skeleton s = test::small_skeleton();
  const Motion m = test::random_motion(s, 5, 30.0, 6);
  const BvhDocument good = default_bvh_layout(s);
  auto expect_rejected = [&](void (*edit)(BvhDocument&), const char* what) {
    BvhDocument layout = good;
    edit(layout);
    EXPECT_THROW(motion_to_bvh(m, layout), InputError) << what;
  };
  expect_rejected([](BvhDocument& d) { d.joints[2].name = "Skull"; }, "renamed joint");
  expect_rejected([](BvhDocument& d) { d.joints.pop_back(); }, "missing joint");
  expect_rejected(
      [](BvhDocument& d) {
        BvhJoint extra = d.joints.back();
        extra.name = "Toe_R";
        extra.parent = 6;
        d.joints.push_back(extra);
      },
      "extra joint");
  expect_rejected([](BvhDocument& d) { d.joints[4].parent = 0; }, "different parent");
  expect_rejected([](BvhDocument& d) { std::swap(d.joints[0].name, d.joints[1].name); }, "different root");
  expect_rejected([](BvhDocument& d) { d.joints[2].channels = {C::Xrotation, C::Yrotation}; }, "two rotation channels");
  expect_rejected([](BvhDocument& d) { d.joints[2].channels.clear(); }, "joint that rotates has no rotation channels");
  expect_rejected([](BvhDocument& d) { d.joints[0].channels.erase(d.joints[0].channels.begin() + 1); },
                  "root moves vertically without a Yposition channel");

  // Without translation or rotation to carry, the missing channels are fine.
  Motion still = m;
  for (int f = 0; f < still.num_frames(); ++f) {
    still.rotation(f, 2) = Eigen::Quaterniond::Identity();
    still.root_positions[f].y() = s.offsets[0].y();
  }
  BvhDocument layout = good;
  layout.joints[2].channels.clear();
  layout.joints[0].channels.erase(layout.joints[0].channels.begin() + 1);
  expect_same_pose(still, through_text(still, layout), 1e-6);

  Motion broken = m;
  broken.rotations.pop_back();
  EXPECT_THROW(motion_to_bvh(broken, good), InputError);
}

TEST(MotionBvhTest, RejectsDocumentsItCannotConvert) {
  BvhDocument doc = parse_bvh(kTwoJoints, "two.bvh");
  BvhDocument two_rotations = doc;
  two_rotations.joints[1].channels = {C::Xrotation, C::Yrotation, C::Xposition};
  EXPECT_THROW(motion_from_bvh(two_rotations), InputError);
  BvhDocument no_frames = doc;
  no_frames.num_frames = 0;
  no_frames.values.clear();
  EXPECT_THROW(motion_from_bvh(no_frames), InputError);
  BvhDocument bad_values = doc;
  bad_values.values.pop_back();
  EXPECT_THROW(motion_from_bvh(bad_values), InputError);
}

TEST(MotionBvhTest, RootWithoutPositionChannelsKeepsItsOffset) {
  BvhDocument doc = parse_bvh(kTwoJoints, "two.bvh");
  doc.joints[0].offset = {0, 100, 0};
  doc.joints[0].channels = {C::Zrotation, C::Xrotation, C::Yrotation};
  doc.values = {90, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  const Motion m = motion_from_bvh(doc);
  EXPECT_LT((m.root_positions[1] - Eigen::Vector3d(0, 1, 0)).norm(), 1e-15);
  expect_same_pose(m, through_text(m, doc), 1e-9);
}

TEST(MotionBvhTest, FpsFromFrameTime) {
  BvhDocument doc = parse_bvh(kTwoJoints, "two.bvh");
  doc.frame_time = 0.008333333;
  EXPECT_EQ(motion_from_bvh(doc).fps, 120.0);
  doc.frame_time = 1.0 / 23.976;
  EXPECT_NEAR(motion_from_bvh(doc).fps, 23.976, 1e-9);
}

TEST(MotionBvhTest, ReadsAndWritesFiles) {
  const std::string dir = test::scratch_dir("motion_bvh");
  const Motion m = test::random_motion(test::small_skeleton(), 20, 30.0, 8);
  write_motion(dir + "/a.bvh", m, default_bvh_layout(m.skeleton));
  BvhDocument layout;
  const Motion back = read_motion(dir + "/a.bvh", &layout);
  EXPECT_EQ(layout.num_frames, 20);
  expect_same_pose(m, back, 1e-6);
  // Conversion errors name the file.
  BvhDocument two = parse_bvh(kTwoJoints, "two.bvh");
  two.joints[1].channels = {C::Xrotation, C::Yrotation, C::Xposition};
  write_bvh_file(dir + "/b.bvh", two);
  try {
    read_motion(dir + "/b.bvh");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(dir + "/b.bvh: ", 0), 0u) << e.what();
  }
  // A file that cannot be read is a FileError (an InputError; MF_ERROR_IO at the C API), naming it and why.
  try {
    read_motion(dir + "/missing.bvh");
    ADD_FAILURE() << "no error";
  } catch (const FileError& e) {
    EXPECT_EQ(std::string(e.what()), "cannot open BVH file " + dir + "/missing.bvh: No such file or directory");
  }
}

// One of the training data's own files, extracted from the shared archive
// (skipped only on a machine without ../shared/data).
TEST(MotionBvhTest, ReadsTheDatasetRig) {
  const std::string archive = default_train_archive();
  if (!std::filesystem::exists(archive)) GTEST_SKIP() << archive << " is not there";
  const std::string member = "Bandai-Namco-Research-Motiondataset-1/data/dataset-1_walk_normal_001.bvh";
  const std::string dir = test::scratch_dir("dataset_rig");
  const std::string command = "tar -xf '" + archive + "' -C '" + dir + "' '" + member + "'";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  const std::string path = dir + "/" + member;
  BvhDocument layout;
  const Motion m = read_motion(path, &layout);
  EXPECT_EQ(layout.joints.size(), 22u);
  EXPECT_EQ(m.num_joints(), 21);
  EXPECT_EQ(m.num_frames(), 195);
  EXPECT_EQ(m.fps, 30.0);
  EXPECT_EQ(m.skeleton.names[0], "Hips");
  const GlobalPose p = forward_kinematics(m);
  EXPECT_NEAR(p.position(0, 0).y(), 0.9, 0.05);
  // Standing ankle height about 11.7 cm (data/README.md).
  double lowest_ankle = 1e9;
  for (int f = 0; f < m.num_frames(); ++f)
    lowest_ankle = std::min(lowest_ankle, p.position(f, m.skeleton.find("Foot_L")).y());
  EXPECT_NEAR(lowest_ankle, 0.117, 0.01);
  expect_same_pose(m, through_text(m, layout), 1e-6);
}

}  // namespace
}  // namespace mf
