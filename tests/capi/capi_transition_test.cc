// mf_transition through the C ABI and motionfield.hpp: the parts kept, the
// chosen length, the options struct's checks, and constraints with frames of
// the output clip.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "motionfield.hpp"
#include "prior/motion/motion_bvh.h"
#include "tests/capi/capi_test_util.h"
#include "tests/test_util.h"

namespace mf::capi_test {
namespace {

struct SolutionDeleter {
  void operator()(mf_solution* s) const { mf_solution_destroy(s); }
};
using SolutionPtr = std::unique_ptr<mf_solution, SolutionDeleter>;

mf_task_options interp_options() {
  mf_task_options o;
  mf_task_options_init(&o);
  o.method = "interp";
  return o;
}

MotionPtr motion_of(const mf_solution* s, int index = 0) {
  mf_motion* m = nullptr;
  EXPECT_EQ(mf_solution_get_motion(s, index, &m), MF_OK) << describe(1);
  return MotionPtr(m);
}

class CApiTransition : public ::testing::Test {
 protected:
  void SetUp() override {
    const Motion walk = read_motion(sample_bvh());
    a_ = to_capi(walk.slice(0, 35));
    b_ = to_capi(walk.slice(20, 61));
  }
  MotionPtr a_, b_;
};

TEST_F(CApiTransition, KeepsThePartsAndReportsTheLength) {
  mf_transition_options t;
  ASSERT_EQ(mf_transition_options_init(&t), MF_OK);
  EXPECT_EQ(t.struct_size, sizeof t);
  EXPECT_EQ(t.from_frame, -1);
  EXPECT_EQ(t.place, MF_PLACE_AUTO);
  t.frames = 12;
  t.place = MF_PLACE_KEEP;
  const mf_task_options o = interp_options();
  mf_solution* raw = nullptr;
  ASSERT_EQ(mf_transition(nullptr, a_.get(), b_.get(), &t, nullptr, 0, &o, &raw), MF_OK) << describe(1);
  SolutionPtr s(raw);
  int32_t frames = 0, first = 0;
  ASSERT_EQ(mf_solution_get_transition(s.get(), &frames, &first), MF_OK);
  EXPECT_EQ(frames, 12);
  EXPECT_EQ(first, 35);
  const MotionPtr out = motion_of(s.get());
  ASSERT_EQ(frame_count(out.get()), 35 + 12 + 41);
  const std::vector<float> ra = rotations(a_.get()), rb = rotations(b_.get()), ro = rotations(out.get());
  const size_t per_frame = ra.size() / 35;
  EXPECT_TRUE(std::equal(ra.begin(), ra.end(), ro.begin()));
  EXPECT_TRUE(std::equal(rb.begin(), rb.end(), ro.begin() + 47 * per_frame));
  // A solution of mf_solve is not a transition's.
  mf_constraints* c = nullptr;
  ASSERT_EQ(mf_constraints_create(&c), MF_OK);
  const int32_t keys[] = {0, 34};
  mf_constraints_add_pose_keys(c, keys, 2);
  mf_solution* solved = nullptr;
  ASSERT_EQ(mf_solve(nullptr, a_.get(), c, 0, &o, &solved), MF_OK) << describe(1);
  EXPECT_EQ(mf_solution_get_transition(solved, &frames, &first), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(mf_last_error_message()).find("not a transition"), std::string::npos);
  mf_solution_destroy(solved);
  mf_constraints_destroy(c);
}

TEST_F(CApiTransition, BadOptionsAndArguments) {
  const mf_task_options o = interp_options();
  mf_solution* s = nullptr;
  mf_transition_options t;
  mf_transition_options_init(&t);
  t.struct_size = 2;
  EXPECT_EQ(mf_transition(nullptr, a_.get(), b_.get(), &t, nullptr, 0, &o, &s), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(mf_last_error_message()).find("mf_transition_options.struct_size"), std::string::npos);
  mf_transition_options_init(&t);
  t.place = 7;
  EXPECT_EQ(mf_transition(nullptr, a_.get(), b_.get(), &t, nullptr, 0, &o, &s), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(mf_last_error_message()).find("place"), std::string::npos);
  mf_transition_options_init(&t);
  t.frames = 601;
  EXPECT_EQ(mf_transition(nullptr, a_.get(), b_.get(), &t, nullptr, 0, &o, &s), MF_ERROR_INVALID_ARGUMENT);
  mf_transition_options_init(&t);
  t.to_frame = 40;
  EXPECT_EQ(mf_transition(nullptr, a_.get(), b_.get(), &t, nullptr, 0, &o, &s), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(mf_last_error_message()).find("to_frame 40 is out of range"), std::string::npos);
  const MotionPtr other = random_capi_motion(30, 30.0, 2);
  EXPECT_EQ(mf_transition(nullptr, a_.get(), other.get(), nullptr, nullptr, 0, &o, &s), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(mf_last_error_message()).find("clip B's rig differs from A's"), std::string::npos);
  EXPECT_EQ(mf_transition(nullptr, a_.get(), b_.get(), nullptr, nullptr, 17, &o, &s), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(s, nullptr);
}

TEST_F(CApiTransition, CppWrapperWithConstraintsOnTheOutputsFrames) {
  namespace api = motionfield;
  const api::Motion a = api::Motion::load_bvh(sample_bvh());
  api::TransitionOptions t;
  t.frames = 10;
  t.from_frame = 30;
  t.to_frame = 20;
  t.place = MF_PLACE_KEEP;
  t.only_transition = true;
  // A target at output frame 36 (the transition's sixth frame), in the file's unit.
  api::Constraints c = api::Constraints::parse_json(
      R"({"targets": [{"frame": 36, "joint": "Hand_R", "position": [0, 100, 0]}]})");
  const api::Solution s = api::transition(api::Model(), a, a, t, c, 0, api::TaskOptions("interp"));
  EXPECT_EQ(s.transition_frames(), 10);
  EXPECT_EQ(s.transition_first_frame(), 31);
  EXPECT_EQ(s.motion(0).frame_count(), 10);
  EXPECT_EQ(s.report(0).targets, 1);
  // Automatic length: reported in the warnings.
  const api::Solution automatic = api::transition(api::Model(), a, a, {}, api::Constraints(), 0, {"interp"});
  EXPECT_GE(automatic.transition_frames(), 10);
  EXPECT_LE(automatic.transition_frames(), 60);
  EXPECT_NE(automatic.motion(0).warnings().find("the transition has"), std::string::npos);
}

}  // namespace
}  // namespace mf::capi_test
