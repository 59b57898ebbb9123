// NULL everywhere (issue 18, docs/RELIABILITY.md "Bad input and faults"):
// every entry point of motionfield.h is called with NULL in each of its
// pointer parameters in turn, the others valid. A required pointer gives
// MF_ERROR_INVALID_ARGUMENT with a message naming it; a pointer the header
// documents as optional (options structs, `needed`, rig maps, ...) gives the
// default behaviour; destroy functions accept NULL; nothing crashes and no
// out-param is written on failure. capi_bad_input_test.cc checks the messages
// of the common entry points in more detail; this file is the complete list.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/capi/capi_test_util.h"
#include "tests/test_util.h"

namespace mf::capi_test {
namespace {

// MF_ERROR_INVALID_ARGUMENT with a message that says which pointer was NULL.
::testing::AssertionResult RefusesNull(int status, const char* what) {
  const std::string message = mf_last_error_message();
  if (status != MF_ERROR_INVALID_ARGUMENT)
    return ::testing::AssertionFailure() << what << ": status " << mf_status_name(status) << " (" << message << ")";
  if (message.find("NULL") == std::string::npos && message.find("null") == std::string::npos)
    return ::testing::AssertionFailure() << what << ": the message '" << message << "' does not say what is NULL";
  return ::testing::AssertionSuccess();
}

::testing::AssertionResult Accepts(int status, const char* what) {
  if (status == MF_OK) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << what << ": status " << mf_status_name(status) << " ("
                                       << mf_last_error_message() << ")";
}

#define EXPECT_REFUSES_NULL(call) EXPECT_TRUE(RefusesNull((call), #call))
#define EXPECT_ACCEPTS(call) EXPECT_TRUE(Accepts((call), #call))

mf_motion* const kMotion = reinterpret_cast<mf_motion*>(0x5eed);
mf_model* const kModel = reinterpret_cast<mf_model*>(0x5eed);
mf_encoding* const kEncoding = reinterpret_cast<mf_encoding*>(0x5eed);
mf_constraints* const kConstraints = reinterpret_cast<mf_constraints*>(0x5eed);
mf_solution* const kSolution = reinterpret_cast<mf_solution*>(0x5eed);
mf_cancel_token* const kToken = reinterpret_cast<mf_cancel_token*>(0x5eed);

class CApiNull : public ::testing::Test {
 protected:
  void SetUp() override {
    model_ = load_tiny_model();
    motion_ = random_capi_motion(20, 30.0, 3);
    mf_encoding* e = nullptr;
    ASSERT_EQ(mf_encode(model_.get(), motion_.get(), nullptr, &e), MF_OK) << describe(1);
    encoding_.reset(e);
  }
  ModelPtr model_;
  MotionPtr motion_;
  EncodingPtr encoding_;
  float f32_[4096] = {};
  int32_t i32_[512] = {};
  char text_[65536] = {};
  size_t needed_ = 0;
};

TEST_F(CApiNull, VersionsStatusesMessagesAndThreads) {
  EXPECT_NE(mf_version_string(), nullptr);
  EXPECT_NE(mf_status_name(-12345), nullptr);
  EXPECT_NE(mf_last_error_message(), nullptr);
  EXPECT_ACCEPTS(mf_printable_text(nullptr, 0, text_, sizeof text_, &needed_));
  EXPECT_REFUSES_NULL(mf_printable_text(nullptr, 5, text_, sizeof text_, &needed_));
  EXPECT_REFUSES_NULL(mf_printable_text("abc", 3, nullptr, 10, &needed_));
  EXPECT_REFUSES_NULL(mf_printable_text("abc", 3, nullptr, 0, nullptr));
  EXPECT_ACCEPTS(mf_printable_text("abc", 3, text_, sizeof text_, nullptr));
  EXPECT_REFUSES_NULL(mf_get_num_threads(nullptr));
}

TEST_F(CApiNull, CancelTokensAndMethods) {
  mf_cancel_token* token = kToken;
  EXPECT_REFUSES_NULL(mf_cancel_token_create(nullptr));
  EXPECT_REFUSES_NULL(mf_cancel_token_cancel(nullptr));
  EXPECT_REFUSES_NULL(mf_cancel_token_reset(nullptr));
  ASSERT_EQ(mf_cancel_token_create(&token), MF_OK);
  EXPECT_REFUSES_NULL(mf_cancel_token_is_cancelled(nullptr, i32_));
  EXPECT_REFUSES_NULL(mf_cancel_token_is_cancelled(token, nullptr));
  mf_cancel_token_destroy(token);
  mf_cancel_token_destroy(nullptr);

  EXPECT_REFUSES_NULL(mf_method_count(nullptr));
  EXPECT_ACCEPTS(mf_method_get(0, nullptr, nullptr, nullptr));  // every out-param is optional
  EXPECT_REFUSES_NULL(mf_method_find(nullptr, i32_));
  EXPECT_REFUSES_NULL(mf_method_find("interp", nullptr));
  const char* name = nullptr;
  EXPECT_ACCEPTS(mf_default_method(nullptr, &name));  // no model: the model-free default
  EXPECT_REFUSES_NULL(mf_default_method(model_.get(), nullptr));
}

TEST_F(CApiNull, Models) {
  EXPECT_REFUSES_NULL(mf_model_default_path(nullptr, 10, &needed_));
  EXPECT_REFUSES_NULL(mf_model_default_path(nullptr, 0, nullptr));
  EXPECT_ACCEPTS(mf_model_default_path(nullptr, 0, &needed_));  // a size query
  mf_model* model = kModel;
  EXPECT_REFUSES_NULL(mf_model_load(tiny_model_path().c_str(), nullptr));
  EXPECT_REFUSES_NULL(mf_model_load_from_memory(nullptr, 100, &model));
  EXPECT_REFUSES_NULL(mf_model_load_from_memory(tiny_model_bytes().data(), tiny_model_bytes().size(), nullptr));
  EXPECT_REFUSES_NULL(mf_model_with_inbetweener(nullptr, tiny_model_path().c_str(), &model));
  EXPECT_REFUSES_NULL(mf_model_with_inbetweener(model_.get(), nullptr, &model));
  EXPECT_REFUSES_NULL(mf_model_with_inbetweener(model_.get(), tiny_model_path().c_str(), nullptr));
  EXPECT_EQ(model, kModel);
  EXPECT_REFUSES_NULL(mf_model_has_inbetweener(nullptr, "twostage", i32_));
  EXPECT_REFUSES_NULL(mf_model_has_inbetweener(model_.get(), nullptr, i32_));
  EXPECT_REFUSES_NULL(mf_model_has_inbetweener(model_.get(), "twostage", nullptr));
  EXPECT_REFUSES_NULL(mf_model_describe(nullptr, text_, sizeof text_, &needed_));
  EXPECT_REFUSES_NULL(mf_model_describe(model_.get(), nullptr, 10, &needed_));
  EXPECT_REFUSES_NULL(mf_model_get_joint_count(nullptr, i32_));
  EXPECT_REFUSES_NULL(mf_model_get_joint_count(model_.get(), nullptr));
  EXPECT_REFUSES_NULL(mf_model_get_joint_name(nullptr, 0, text_, sizeof text_, &needed_));
  EXPECT_REFUSES_NULL(mf_model_get_joint_name(model_.get(), 0, nullptr, 10, &needed_));
  EXPECT_REFUSES_NULL(mf_model_get_parents(nullptr, i32_, 512, &needed_));
  EXPECT_REFUSES_NULL(mf_model_get_parents(model_.get(), nullptr, 512, &needed_));
  EXPECT_REFUSES_NULL(mf_model_get_offsets(nullptr, f32_, 4096, &needed_));
  EXPECT_REFUSES_NULL(mf_model_get_offsets(model_.get(), nullptr, 4096, &needed_));
  double f64 = 0;
  EXPECT_REFUSES_NULL(mf_model_get_fps(nullptr, &f64));
  EXPECT_REFUSES_NULL(mf_model_get_fps(model_.get(), nullptr));
  EXPECT_REFUSES_NULL(mf_model_get_window(nullptr, i32_));
  EXPECT_REFUSES_NULL(mf_model_get_window(model_.get(), nullptr));
  EXPECT_REFUSES_NULL(mf_model_get_latent_sizes(nullptr, i32_, i32_ + 1));
  // Either size may be NULL (the caller wants the other); both NULL is refused.
  EXPECT_REFUSES_NULL(mf_model_get_latent_sizes(model_.get(), nullptr, nullptr));
  EXPECT_ACCEPTS(mf_model_get_latent_sizes(model_.get(), nullptr, i32_ + 1));
  EXPECT_ACCEPTS(mf_model_get_latent_sizes(model_.get(), i32_, nullptr));
  mf_model_destroy(nullptr);
}

TEST_F(CApiNull, MotionsFromArraysAndBvh) {
  const int32_t joints = 7, frames = 2;
  std::vector<std::string> names = {"Hips", "Spine", "Head", "UpperLeg_L", "Foot_L", "UpperLeg_R", "Foot_R"};
  std::vector<const char*> name_ptrs;
  for (const std::string& n : names) name_ptrs.push_back(n.c_str());
  const int32_t parents[] = {-1, 0, 1, 0, 3, 0, 5};
  std::vector<float> offsets(3 * joints, 0.1f), rotations, root(3 * frames, 0.0f);
  for (int i = 0; i < joints * frames; ++i) rotations.insert(rotations.end(), {1, 0, 0, 0});
  mf_motion* m = kMotion;
  EXPECT_REFUSES_NULL(mf_motion_create(joints, nullptr, parents, offsets.data(), frames, 30, rotations.data(),
                                       root.data(), &m));
  EXPECT_REFUSES_NULL(mf_motion_create(joints, name_ptrs.data(), nullptr, offsets.data(), frames, 30,
                                       rotations.data(), root.data(), &m));
  EXPECT_REFUSES_NULL(mf_motion_create(joints, name_ptrs.data(), parents, nullptr, frames, 30, rotations.data(),
                                       root.data(), &m));
  EXPECT_REFUSES_NULL(mf_motion_create(joints, name_ptrs.data(), parents, offsets.data(), frames, 30, nullptr,
                                       root.data(), &m));
  EXPECT_REFUSES_NULL(mf_motion_create(joints, name_ptrs.data(), parents, offsets.data(), frames, 30,
                                       rotations.data(), nullptr, &m));
  EXPECT_REFUSES_NULL(mf_motion_create(joints, name_ptrs.data(), parents, offsets.data(), frames, 30,
                                       rotations.data(), root.data(), nullptr));
  EXPECT_REFUSES_NULL(mf_motion_create_for_model(nullptr, joints, frames, 30, rotations.data(), root.data(), &m));
  EXPECT_REFUSES_NULL(mf_motion_create_for_model(model_.get(), joints, frames, 30, nullptr, root.data(), &m));
  EXPECT_REFUSES_NULL(mf_motion_create_for_model(model_.get(), joints, frames, 30, rotations.data(), nullptr, &m));
  EXPECT_REFUSES_NULL(
      mf_motion_create_for_model(model_.get(), joints, frames, 30, rotations.data(), root.data(), nullptr));
  EXPECT_REFUSES_NULL(mf_motion_create_like(nullptr, joints, frames, 30, rotations.data(), root.data(), &m));
  EXPECT_REFUSES_NULL(mf_motion_create_like(motion_.get(), joints, frames, 30, nullptr, root.data(), &m));
  EXPECT_REFUSES_NULL(mf_motion_create_like(motion_.get(), joints, frames, 30, rotations.data(), nullptr, &m));
  EXPECT_REFUSES_NULL(
      mf_motion_create_like(motion_.get(), joints, frames, 30, rotations.data(), root.data(), nullptr));
  EXPECT_EQ(m, kMotion);

  EXPECT_REFUSES_NULL(mf_bvh_options_init(nullptr));
  EXPECT_REFUSES_NULL(mf_motion_load_bvh(nullptr, nullptr, &m));
  EXPECT_REFUSES_NULL(mf_motion_load_bvh(sample_bvh().c_str(), nullptr, nullptr));
  EXPECT_REFUSES_NULL(mf_motion_load_bvh_from_memory(nullptr, 10, nullptr, &m));
  EXPECT_REFUSES_NULL(mf_motion_load_bvh_from_memory("HIERARCHY", 9, nullptr, nullptr));
  EXPECT_EQ(m, kMotion);
  EXPECT_REFUSES_NULL(mf_motion_save_bvh(nullptr, "/dev/null", nullptr));
  EXPECT_REFUSES_NULL(mf_motion_save_bvh(motion_.get(), nullptr, nullptr));
  EXPECT_ACCEPTS(mf_motion_save_bvh(motion_.get(), "/dev/null", nullptr));  // options: the defaults
  EXPECT_REFUSES_NULL(mf_motion_save_bvh_to_memory(nullptr, nullptr, text_, sizeof text_, &needed_));
  EXPECT_REFUSES_NULL(mf_motion_save_bvh_to_memory(motion_.get(), nullptr, nullptr, 10, &needed_));
  EXPECT_REFUSES_NULL(mf_motion_save_bvh_to_memory(motion_.get(), nullptr, nullptr, 0, nullptr));
  EXPECT_ACCEPTS(mf_motion_save_bvh_to_memory(motion_.get(), nullptr, nullptr, 0, &needed_));
  mf_motion_destroy(nullptr);
}

TEST_F(CApiNull, MotionGetters) {
  double f64 = 0;
  const mf_motion* m = motion_.get();
  EXPECT_REFUSES_NULL(mf_motion_get_joint_count(nullptr, i32_));
  EXPECT_REFUSES_NULL(mf_motion_get_joint_count(m, nullptr));
  EXPECT_REFUSES_NULL(mf_motion_get_frame_count(nullptr, i32_));
  EXPECT_REFUSES_NULL(mf_motion_get_frame_count(m, nullptr));
  EXPECT_REFUSES_NULL(mf_motion_get_fps(nullptr, &f64));
  EXPECT_REFUSES_NULL(mf_motion_get_fps(m, nullptr));
  EXPECT_REFUSES_NULL(mf_motion_get_frame_time(nullptr, &f64));
  EXPECT_REFUSES_NULL(mf_motion_get_frame_time(m, nullptr));
  EXPECT_REFUSES_NULL(mf_motion_get_length_scale(nullptr, &f64));
  EXPECT_REFUSES_NULL(mf_motion_get_length_scale(m, nullptr));
  EXPECT_REFUSES_NULL(mf_motion_get_joint_name(nullptr, 0, text_, sizeof text_, &needed_));
  EXPECT_REFUSES_NULL(mf_motion_get_joint_name(m, 0, nullptr, 10, &needed_));
  EXPECT_REFUSES_NULL(mf_motion_get_parents(nullptr, i32_, 512, &needed_));
  EXPECT_REFUSES_NULL(mf_motion_get_parents(m, nullptr, 512, &needed_));
  EXPECT_REFUSES_NULL(mf_motion_get_offsets(nullptr, f32_, 4096, &needed_));
  EXPECT_REFUSES_NULL(mf_motion_get_offsets(m, nullptr, 4096, &needed_));
  EXPECT_REFUSES_NULL(mf_motion_get_rotations(nullptr, f32_, 4096, &needed_));
  EXPECT_REFUSES_NULL(mf_motion_get_rotations(m, nullptr, 4096, &needed_));
  EXPECT_REFUSES_NULL(mf_motion_get_root_positions(nullptr, f32_, 4096, &needed_));
  EXPECT_REFUSES_NULL(mf_motion_get_root_positions(m, nullptr, 4096, &needed_));
  EXPECT_REFUSES_NULL(mf_motion_get_global_positions(nullptr, f32_, 4096, &needed_));
  EXPECT_REFUSES_NULL(mf_motion_get_global_positions(m, nullptr, 4096, &needed_));
  EXPECT_REFUSES_NULL(mf_motion_get_warnings(nullptr, text_, sizeof text_, &needed_));
  EXPECT_REFUSES_NULL(mf_motion_get_warnings(m, nullptr, 10, &needed_));
  EXPECT_ACCEPTS(mf_motion_get_rotations(m, f32_, 4096, nullptr));  // `needed` is optional with a buffer
}

TEST_F(CApiNull, Gltf) {
  EXPECT_REFUSES_NULL(mf_gltf_options_init(nullptr));
  EXPECT_REFUSES_NULL(mf_motion_save_gltf(nullptr, "/dev/null", nullptr));
  EXPECT_REFUSES_NULL(mf_motion_save_gltf(motion_.get(), nullptr, nullptr));
  EXPECT_REFUSES_NULL(mf_motion_save_gltf_to_memory(nullptr, nullptr, nullptr, 0, &needed_));
  EXPECT_REFUSES_NULL(mf_motion_save_gltf_to_memory(motion_.get(), nullptr, nullptr, 10, &needed_));
  EXPECT_ACCEPTS(mf_motion_save_gltf_to_memory(motion_.get(), nullptr, nullptr, 0, &needed_));
}

TEST_F(CApiNull, Tasks) {
  const int32_t keys[] = {0, 10, 19};
  mf_motion* m = kMotion;
  EXPECT_REFUSES_NULL(mf_task_options_init(nullptr));
  EXPECT_REFUSES_NULL(mf_inbetween(model_.get(), nullptr, keys, 3, nullptr, &m));
  EXPECT_REFUSES_NULL(mf_inbetween(model_.get(), motion_.get(), nullptr, 3, nullptr, &m));
  EXPECT_REFUSES_NULL(mf_inbetween(model_.get(), motion_.get(), keys, 3, nullptr, nullptr));
  EXPECT_REFUSES_NULL(mf_fill(model_.get(), nullptr, 5, 10, nullptr, &m));
  EXPECT_REFUSES_NULL(mf_fill(model_.get(), motion_.get(), 5, 10, nullptr, nullptr));
  EXPECT_REFUSES_NULL(mf_resample(model_.get(), nullptr, 60.0, nullptr, &m));
  EXPECT_REFUSES_NULL(mf_resample(model_.get(), motion_.get(), 60.0, nullptr, nullptr));
  EXPECT_EQ(m, kMotion);
  // No model and no options: the model-free default method.
  mf_task_options interp;
  mf_task_options_init(&interp);
  interp.method = "interp";
  EXPECT_ACCEPTS(mf_inbetween(nullptr, motion_.get(), keys, 3, nullptr, &m));
  mf_motion_destroy(m);
  EXPECT_REFUSES_NULL(mf_resample_frame_count(20, 30.0, 60.0, nullptr, i32_));
  EXPECT_ACCEPTS(mf_resample_frame_count(20, 30.0, 60.0, i32_, nullptr));  // `rounded` is optional

  const float path[] = {0.0f, 0.0f, 0.0f, 0.5f, 0.0f, 1.0f};
  m = kMotion;
  EXPECT_REFUSES_NULL(mf_renav_options_init(nullptr));
  EXPECT_REFUSES_NULL(mf_renav(model_.get(), nullptr, path, 3, nullptr, nullptr, &m));
  EXPECT_REFUSES_NULL(mf_renav(model_.get(), motion_.get(), nullptr, 3, nullptr, nullptr, &m));
  EXPECT_REFUSES_NULL(mf_renav(model_.get(), motion_.get(), path, 3, nullptr, nullptr, nullptr));
  EXPECT_EQ(mf_renav(nullptr, motion_.get(), path, 3, nullptr, nullptr, &m), MF_ERROR_MODEL);
  EXPECT_EQ(m, kMotion);
  EXPECT_REFUSES_NULL(mf_path_load_csv(nullptr, f32_, 4096, &needed_));
}

TEST_F(CApiNull, EncodeAndDecode) {
  mf_encoding* e = kEncoding;
  mf_motion* m = kMotion;
  const mf_encoding* code = encoding_.get();
  double f64 = 0;
  EXPECT_REFUSES_NULL(mf_codec_options_init(nullptr));
  EXPECT_REFUSES_NULL(mf_encode(nullptr, motion_.get(), nullptr, &e));
  EXPECT_REFUSES_NULL(mf_encode(model_.get(), nullptr, nullptr, &e));
  EXPECT_REFUSES_NULL(mf_encode(model_.get(), motion_.get(), nullptr, nullptr));
  EXPECT_REFUSES_NULL(mf_encoding_get_window_count(nullptr, i32_));
  EXPECT_REFUSES_NULL(mf_encoding_get_window_count(code, nullptr));
  EXPECT_REFUSES_NULL(mf_encoding_get_duration(nullptr, &f64));
  EXPECT_REFUSES_NULL(mf_encoding_get_duration(code, nullptr));
  EXPECT_REFUSES_NULL(mf_encoding_get_window_times(nullptr, &f64, 1, &needed_));
  EXPECT_REFUSES_NULL(mf_encoding_get_window_times(code, nullptr, 1, &needed_));
  EXPECT_REFUSES_NULL(mf_encoding_get_local_latents(nullptr, f32_, 4096, &needed_));
  EXPECT_REFUSES_NULL(mf_encoding_get_local_latents(code, nullptr, 4096, &needed_));
  EXPECT_REFUSES_NULL(mf_encoding_get_global_latents(nullptr, f32_, 4096, &needed_));
  EXPECT_REFUSES_NULL(mf_encoding_get_global_latents(code, nullptr, 4096, &needed_));
  EXPECT_REFUSES_NULL(mf_encoding_with_latents(nullptr, nullptr, 0, nullptr, 0, &e));
  EXPECT_REFUSES_NULL(mf_encoding_with_latents(code, nullptr, 8, nullptr, 0, &e));
  EXPECT_REFUSES_NULL(mf_encoding_with_latents(code, nullptr, 0, nullptr, 4, &e));
  EXPECT_REFUSES_NULL(mf_encoding_with_latents(code, nullptr, 0, nullptr, 0, nullptr));
  EXPECT_EQ(e, kEncoding);
  EXPECT_ACCEPTS(mf_encoding_with_latents(code, nullptr, 0, nullptr, 0, &e));  // NULL with count 0: kept
  mf_encoding_destroy(e);
  EXPECT_REFUSES_NULL(mf_decode(nullptr, 30.0, 0, nullptr, &m));
  EXPECT_REFUSES_NULL(mf_decode(code, 30.0, 0, nullptr, nullptr));
  const double t = 0.1;
  EXPECT_REFUSES_NULL(mf_decode_times(nullptr, &t, 1, 30.0, nullptr, &m));
  EXPECT_REFUSES_NULL(mf_decode_times(code, nullptr, 1, 30.0, nullptr, &m));
  EXPECT_REFUSES_NULL(mf_decode_times(code, &t, 1, 30.0, nullptr, nullptr));
  EXPECT_EQ(m, kMotion);
  mf_encoding_destroy(nullptr);
}

TEST_F(CApiNull, UnitsAndRigs) {
  double f64 = 0;
  EXPECT_REFUSES_NULL(mf_length_unit_scale(nullptr, &f64));
  EXPECT_REFUSES_NULL(mf_length_unit_scale("cm", nullptr));
  EXPECT_REFUSES_NULL(mf_rig_describe(model_.get(), nullptr, nullptr, text_, sizeof text_, &needed_));
  EXPECT_EQ(mf_rig_describe(nullptr, motion_.get(), nullptr, text_, sizeof text_, &needed_), MF_ERROR_MODEL);
  // A rig the model can map (the tiny model has no humanoid anatomy): the
  // bundled model and sample.
  mf_model* bundled = nullptr;
  ASSERT_EQ(mf_model_load((std::string(MF_SOURCE_DIR) + "/models/motionfield-prior.mfm").c_str(), &bundled), MF_OK)
      << describe(1);
  const ModelPtr bundled_model(bundled);
  mf_motion* walk = nullptr;
  ASSERT_EQ(mf_motion_load_bvh(sample_bvh().c_str(), nullptr, &walk), MF_OK) << describe(1);
  const MotionPtr sample(walk);
  EXPECT_REFUSES_NULL(mf_rig_describe(bundled, walk, nullptr, nullptr, 10, &needed_));
  EXPECT_ACCEPTS(mf_rig_describe(bundled, walk, nullptr, text_, sizeof text_, &needed_));  // NULL map: automatic
}

TEST_F(CApiNull, ConstraintsAndSolutions) {
  mf_constraints* c = kConstraints;
  EXPECT_REFUSES_NULL(mf_constraints_create(nullptr));
  EXPECT_REFUSES_NULL(mf_constraints_parse_json(nullptr, 2, &c));
  EXPECT_REFUSES_NULL(mf_constraints_parse_json("{}", 2, nullptr));
  EXPECT_REFUSES_NULL(mf_constraints_load_json(nullptr, &c));
  EXPECT_REFUSES_NULL(mf_constraints_load_json("/dev/null", nullptr));
  EXPECT_EQ(c, kConstraints);
  ASSERT_EQ(mf_constraints_create(&c), MF_OK);
  const int32_t frames[] = {0, 19};
  const float position[] = {0, 1, 0};
  const char* joints[] = {"Head", nullptr};
  EXPECT_REFUSES_NULL(mf_constraints_add_pose_keys(nullptr, frames, 2));
  EXPECT_REFUSES_NULL(mf_constraints_add_pose_keys(c, nullptr, 2));
  EXPECT_REFUSES_NULL(mf_constraints_add_partial_key(nullptr, 5, joints, 1, MF_ROOT_NONE));
  EXPECT_REFUSES_NULL(mf_constraints_add_partial_key(c, 5, nullptr, 1, MF_ROOT_NONE));
  EXPECT_REFUSES_NULL(mf_constraints_add_partial_key(c, 5, joints, 2, MF_ROOT_NONE));  // joints[1] is NULL
  EXPECT_REFUSES_NULL(mf_constraints_add_target(nullptr, 5, "Head", position, 1.0f));
  EXPECT_REFUSES_NULL(mf_constraints_add_target(c, 5, nullptr, position, 1.0f));
  EXPECT_REFUSES_NULL(mf_constraints_add_target(c, 5, "Head", nullptr, 1.0f));
  EXPECT_REFUSES_NULL(mf_constraints_add_contact(nullptr, "Foot_L", 2, 5));
  EXPECT_REFUSES_NULL(mf_constraints_add_contact(c, nullptr, 2, 5));
  EXPECT_REFUSES_NULL(mf_constraints_to_json(nullptr, text_, sizeof text_, &needed_));
  EXPECT_REFUSES_NULL(mf_constraints_to_json(c, nullptr, 10, &needed_));
  ASSERT_EQ(mf_constraints_add_pose_keys(c, frames, 2), MF_OK) << describe(1);

  mf_solution* s = kSolution;
  mf_task_options interp;
  mf_task_options_init(&interp);
  interp.method = "interp";
  EXPECT_REFUSES_NULL(mf_solve(model_.get(), nullptr, c, 0, &interp, &s));
  EXPECT_REFUSES_NULL(mf_solve(model_.get(), motion_.get(), nullptr, 0, &interp, &s));
  EXPECT_REFUSES_NULL(mf_solve(model_.get(), motion_.get(), c, 0, &interp, nullptr));
  EXPECT_EQ(s, kSolution);
  ASSERT_EQ(mf_solve(nullptr, motion_.get(), c, 0, &interp, &s), MF_OK) << describe(1);  // interp needs no model
  mf_motion* m = kMotion;
  mf_constraint_report report;
  EXPECT_REFUSES_NULL(mf_constraint_report_init(nullptr));
  mf_constraint_report_init(&report);
  EXPECT_REFUSES_NULL(mf_solution_get_count(nullptr, i32_));
  EXPECT_REFUSES_NULL(mf_solution_get_count(s, nullptr));
  EXPECT_REFUSES_NULL(mf_solution_get_motion(nullptr, 0, &m));
  EXPECT_REFUSES_NULL(mf_solution_get_motion(s, 0, nullptr));
  EXPECT_EQ(m, kMotion);
  EXPECT_REFUSES_NULL(mf_solution_get_report(nullptr, 0, &report));
  EXPECT_REFUSES_NULL(mf_solution_get_report(s, 0, nullptr));
  EXPECT_REFUSES_NULL(mf_solution_get_report_json(nullptr, text_, sizeof text_, &needed_));
  EXPECT_REFUSES_NULL(mf_solution_get_report_json(s, nullptr, 10, &needed_));
  const char* name = nullptr;
  EXPECT_REFUSES_NULL(mf_solution_get_method(nullptr, &name));
  EXPECT_REFUSES_NULL(mf_solution_get_method(s, nullptr));
  EXPECT_ACCEPTS(mf_solution_get_method(s, &name));
  EXPECT_STREQ(name, "interp");
  mf_solution_destroy(s);
  mf_solution_destroy(nullptr);
  mf_constraints_destroy(c);
  mf_constraints_destroy(nullptr);
}

TEST_F(CApiNull, Transitions) {
  mf_solution* s = kSolution;
  mf_task_options interp;
  mf_task_options_init(&interp);
  interp.method = "interp";
  EXPECT_REFUSES_NULL(mf_transition_options_init(nullptr));
  EXPECT_REFUSES_NULL(mf_transition(nullptr, nullptr, motion_.get(), nullptr, nullptr, 0, &interp, &s));
  EXPECT_REFUSES_NULL(mf_transition(nullptr, motion_.get(), nullptr, nullptr, nullptr, 0, &interp, &s));
  EXPECT_REFUSES_NULL(mf_transition(nullptr, motion_.get(), motion_.get(), nullptr, nullptr, 0, &interp, nullptr));
  EXPECT_EQ(s, kSolution);
  // The transition options and the constraints are optional.
  ASSERT_EQ(mf_transition(nullptr, motion_.get(), motion_.get(), nullptr, nullptr, 0, &interp, &s), MF_OK)
      << describe(1);
  int32_t frames = 0;
  EXPECT_REFUSES_NULL(mf_solution_get_transition(nullptr, &frames, nullptr));
  EXPECT_ACCEPTS(mf_solution_get_transition(s, nullptr, nullptr));
  EXPECT_ACCEPTS(mf_solution_get_transition(s, &frames, nullptr));
  EXPECT_GE(frames, 10);
  mf_solution_destroy(s);
}

TEST_F(CApiNull, OutputSetsAndRigMapFiles) {
  const std::string dir = test::scratch_dir("capi-null-outputs-" + std::to_string(::getpid()));
  const std::string out = dir + "/o.bvh";
  mf_output_set* const kSet = reinterpret_cast<mf_output_set*>(0x5eed);
  mf_output_set* s = kSet;
  EXPECT_REFUSES_NULL(mf_output_set_create(nullptr));
  EXPECT_ACCEPTS(mf_output_set_create(&s));
  ASSERT_NE(s, kSet);
  mf_output_set* job = nullptr;
  ASSERT_EQ(mf_output_set_create(&job), MF_OK);
  EXPECT_REFUSES_NULL(mf_output_set_add_input(nullptr, "a.bvh", "input"));
  EXPECT_REFUSES_NULL(mf_output_set_add_input(s, nullptr, "input"));
  EXPECT_REFUSES_NULL(mf_output_set_add_input(s, "a.bvh", nullptr));
  EXPECT_REFUSES_NULL(mf_output_set_add_output(nullptr, out.c_str(), "output"));
  EXPECT_REFUSES_NULL(mf_output_set_add_output(s, nullptr, "output"));
  EXPECT_REFUSES_NULL(mf_output_set_add_output(s, out.c_str(), nullptr));
  EXPECT_ACCEPTS(mf_output_set_add_output(job, out.c_str(), "output"));
  EXPECT_REFUSES_NULL(mf_output_set_merge(nullptr, job, "line 1"));
  EXPECT_REFUSES_NULL(mf_output_set_merge(s, nullptr, "line 1"));
  EXPECT_REFUSES_NULL(mf_output_set_merge(s, job, nullptr));
  EXPECT_ACCEPTS(mf_output_set_merge(s, job, "line 1"));
  EXPECT_REFUSES_NULL(mf_output_set_write(nullptr, out.c_str(), "x", 1));
  EXPECT_REFUSES_NULL(mf_output_set_write(job, nullptr, "x", 1));
  EXPECT_REFUSES_NULL(mf_output_set_write(job, out.c_str(), nullptr, 1));
  EXPECT_ACCEPTS(mf_output_set_write(job, out.c_str(), nullptr, 0));  // no bytes: an empty file
  EXPECT_REFUSES_NULL(mf_output_set_commit(nullptr));
  EXPECT_ACCEPTS(mf_output_set_commit(job));
  EXPECT_TRUE(std::filesystem::is_regular_file(out));
  mf_output_set_destroy(job);
  mf_output_set_destroy(s);
  mf_output_set_destroy(nullptr);
  EXPECT_REFUSES_NULL(mf_rig_map_read_file(nullptr, text_, sizeof text_, &needed_));
  std::ofstream(dir + "/map.json") << "{}";
  EXPECT_REFUSES_NULL(mf_rig_map_read_file((dir + "/map.json").c_str(), nullptr, 10, &needed_));
  EXPECT_ACCEPTS(mf_rig_map_read_file((dir + "/map.json").c_str(), text_, sizeof text_, nullptr));
  std::error_code ignored;
  std::filesystem::remove_all(dir, ignored);
}

}  // namespace
}  // namespace mf::capi_test
