// Bad input at the C boundary: NULL pointers, buffers too small, non-finite
// numbers, joint counts that do not match, frame indices out of range, options
// from older and newer callers, files that are not what they claim. Each call
// must return its status with a message, never crash, and leave the caller's
// out-params and buffers untouched.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "tests/capi/capi_test_util.h"
#include "tests/test_util.h"

namespace mf::capi_test {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// The call's status is `status`, the thread's message is non-empty and
// contains `text`.
::testing::AssertionResult Fails(int got, int status, const std::string& text = "") {
  const std::string message = mf_last_error_message();
  if (got != status)
    return ::testing::AssertionFailure() << "status " << mf_status_name(got) << ", expected " << mf_status_name(status)
                                         << " (message: " << message << ")";
  if (message.empty()) return ::testing::AssertionFailure() << "no message";
  if (message.find(text) == std::string::npos)
    return ::testing::AssertionFailure() << "message '" << message << "' lacks '" << text << "'";
  return ::testing::AssertionSuccess();
}

// Sentinels that must survive failed calls.
mf_motion* const kMotionSentinel = reinterpret_cast<mf_motion*>(0x5eed);
mf_model* const kModelSentinel = reinterpret_cast<mf_model*>(0x5eed);
mf_encoding* const kEncodingSentinel = reinterpret_cast<mf_encoding*>(0x5eed);

std::string scratch() { return test::scratch_dir("capi-bad-" + std::to_string(::getpid())); }

void write_file(const std::string& path, const void* data, size_t size) {
  std::ofstream out(path, std::ios::binary);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
}

struct Arrays {
  std::vector<std::string> names{"Hips", "Spine", "Head", "UpperLeg_L", "Foot_L", "UpperLeg_R", "Foot_R"};
  std::vector<const char*> name_ptrs;
  std::vector<int32_t> parents{-1, 0, 1, 0, 3, 0, 5};
  std::vector<float> offsets = std::vector<float>(21, 0.1f);
  std::vector<float> rotations, root;
  int frames = 5;
  Arrays() {
    for (const std::string& n : names) name_ptrs.push_back(n.c_str());
    for (int i = 0; i < frames * 7; ++i) rotations.insert(rotations.end(), {1.0f, 0.0f, 0.0f, 0.0f});
    root.assign(3 * frames, 0.5f);
  }
  int create(mf_motion** out) const {
    return mf_motion_create(7, name_ptrs.data(), parents.data(), offsets.data(), frames, 30.0, rotations.data(),
                            root.data(), out);
  }
};

TEST(CApiBadInput, NullPointers) {
  const Arrays a;
  mf_motion* m = kMotionSentinel;
  EXPECT_TRUE(Fails(a.create(nullptr), MF_ERROR_INVALID_ARGUMENT, "out is NULL"));
  EXPECT_TRUE(Fails(mf_motion_create(7, nullptr, a.parents.data(), a.offsets.data(), 5, 30.0, a.rotations.data(),
                                     a.root.data(), &m),
                    MF_ERROR_INVALID_ARGUMENT, "joint_names is NULL"));
  std::vector<const char*> names = a.name_ptrs;
  names[3] = nullptr;
  EXPECT_TRUE(Fails(mf_motion_create(7, names.data(), a.parents.data(), a.offsets.data(), 5, 30.0, a.rotations.data(),
                                     a.root.data(), &m),
                    MF_ERROR_INVALID_ARGUMENT, "joint_names[3] is NULL"));
  EXPECT_TRUE(Fails(mf_motion_create(7, a.name_ptrs.data(), a.parents.data(), a.offsets.data(), 5, 30.0, nullptr,
                                     a.root.data(), &m),
                    MF_ERROR_INVALID_ARGUMENT, "rotations is NULL"));
  EXPECT_EQ(m, kMotionSentinel);
  EXPECT_TRUE(Fails(mf_motion_load_bvh(nullptr, nullptr, &m), MF_ERROR_INVALID_ARGUMENT, "path is NULL"));
  EXPECT_TRUE(Fails(mf_motion_load_bvh(sample_bvh().c_str(), nullptr, nullptr), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_motion_load_bvh_from_memory(nullptr, 10, nullptr, &m), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_EQ(m, kMotionSentinel);

  mf_model* model = kModelSentinel;
  EXPECT_TRUE(Fails(mf_model_load(tiny_model_path().c_str(), nullptr), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_model_load_from_memory(nullptr, 100, &model), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_EQ(model, kModelSentinel);
  int32_t i32 = 77;
  double f64 = 77;
  EXPECT_TRUE(Fails(mf_model_get_joint_count(nullptr, &i32), MF_ERROR_INVALID_ARGUMENT, "model is NULL"));
  EXPECT_TRUE(Fails(mf_model_get_fps(nullptr, &f64), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_model_get_latent_sizes(nullptr, &i32, &i32), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_motion_get_frame_count(nullptr, &i32), MF_ERROR_INVALID_ARGUMENT, "motion is NULL"));
  EXPECT_TRUE(Fails(mf_motion_get_fps(nullptr, &f64), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_EQ(i32, 77);
  EXPECT_EQ(f64, 77);

  MotionPtr input;
  {
    mf_motion* raw = nullptr;
    ASSERT_EQ(a.create(&raw), MF_OK);
    input.reset(raw);
  }
  EXPECT_TRUE(Fails(mf_motion_get_frame_count(input.get(), nullptr), MF_ERROR_INVALID_ARGUMENT, "out is NULL"));
  const int32_t keys[] = {0, 4};
  m = kMotionSentinel;
  EXPECT_TRUE(Fails(mf_inbetween(nullptr, nullptr, keys, 2, nullptr, &m), MF_ERROR_INVALID_ARGUMENT, "input is NULL"));
  EXPECT_TRUE(Fails(mf_inbetween(nullptr, input.get(), nullptr, 2, nullptr, &m), MF_ERROR_INVALID_ARGUMENT,
                    "keyframes is NULL"));
  EXPECT_TRUE(Fails(mf_inbetween(nullptr, input.get(), keys, 2, nullptr, nullptr), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_fill(nullptr, nullptr, 1, 2, nullptr, &m), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_resample(nullptr, nullptr, 60.0, nullptr, &m), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_motion_save_bvh(input.get(), nullptr, nullptr), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_motion_save_bvh(nullptr, "x.bvh", nullptr), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_EQ(m, kMotionSentinel);

  EXPECT_TRUE(Fails(mf_cancel_token_create(nullptr), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_cancel_token_cancel(nullptr), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_cancel_token_is_cancelled(nullptr, &i32), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_task_options_init(nullptr), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_bvh_options_init(nullptr), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_codec_options_init(nullptr), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_method_count(nullptr), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_method_find(nullptr, &i32), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_default_method(nullptr, nullptr), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_get_num_threads(nullptr), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_resample_frame_count(61, 30, 60, nullptr, nullptr), MF_ERROR_INVALID_ARGUMENT));

  mf_encoding* e = kEncodingSentinel;
  EXPECT_TRUE(Fails(mf_encode(nullptr, input.get(), nullptr, &e), MF_ERROR_INVALID_ARGUMENT, "model is NULL"));
  EXPECT_TRUE(Fails(mf_decode(nullptr, 30.0, 0, nullptr, &m), MF_ERROR_INVALID_ARGUMENT, "encoding is NULL"));
  const double t = 0.0;
  EXPECT_TRUE(Fails(mf_decode_times(nullptr, &t, 1, 30.0, nullptr, &m), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_encoding_get_window_count(nullptr, &i32), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_EQ(e, kEncodingSentinel);
  EXPECT_EQ(m, kMotionSentinel);
}

TEST(CApiBadInput, BuffersTooSmallAreUntouchedAndTellTheSize) {
  const MotionPtr m = random_capi_motion(6, 30.0, 2);
  const size_t rot_size = 6 * 7 * 4;
  std::vector<float> buffer(rot_size, -42.0f);
  size_t needed = 0;
  EXPECT_TRUE(Fails(mf_motion_get_rotations(m.get(), buffer.data(), rot_size - 1, &needed), MF_ERROR_BUFFER_TOO_SMALL,
                    std::to_string(rot_size)));
  EXPECT_EQ(needed, rot_size);
  for (float v : buffer) ASSERT_EQ(v, -42.0f);
  // NULL `needed` is fine; a NULL buffer with a capacity is not; a size query
  // needs `needed`.
  EXPECT_TRUE(Fails(mf_motion_get_rotations(m.get(), buffer.data(), 3, nullptr), MF_ERROR_BUFFER_TOO_SMALL));
  EXPECT_TRUE(Fails(mf_motion_get_rotations(m.get(), nullptr, 10, &needed), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_TRUE(Fails(mf_motion_get_rotations(m.get(), nullptr, 0, nullptr), MF_ERROR_INVALID_ARGUMENT));
  for (float v : buffer) ASSERT_EQ(v, -42.0f);

  needed = 0;
  EXPECT_TRUE(Fails(mf_motion_get_root_positions(m.get(), buffer.data(), 17, &needed), MF_ERROR_BUFFER_TOO_SMALL));
  EXPECT_EQ(needed, 18u);
  EXPECT_TRUE(Fails(mf_motion_get_global_positions(m.get(), buffer.data(), 5, &needed), MF_ERROR_BUFFER_TOO_SMALL));
  EXPECT_EQ(needed, 6u * 7 * 3);
  EXPECT_TRUE(Fails(mf_motion_get_offsets(m.get(), buffer.data(), 20, &needed), MF_ERROR_BUFFER_TOO_SMALL));
  EXPECT_EQ(needed, 21u);
  int32_t parents[6] = {9, 9, 9, 9, 9, 9};
  EXPECT_TRUE(Fails(mf_motion_get_parents(m.get(), parents, 6, &needed), MF_ERROR_BUFFER_TOO_SMALL));
  EXPECT_EQ(needed, 7u);
  for (int32_t p : parents) EXPECT_EQ(p, 9);
  for (float v : buffer) ASSERT_EQ(v, -42.0f);

  // Strings: the capacity counts the NUL.
  char name[5] = {'x', 'x', 'x', 'x', 'x'};
  EXPECT_TRUE(Fails(mf_motion_get_joint_name(m.get(), 1, name, 5, &needed), MF_ERROR_BUFFER_TOO_SMALL));  // "Spine"
  EXPECT_EQ(needed, 6u);
  for (char c : name) EXPECT_EQ(c, 'x');
  const ModelPtr model = load_tiny_model();
  EXPECT_TRUE(Fails(mf_model_get_joint_name(model.get(), 0, name, 4, &needed), MF_ERROR_BUFFER_TOO_SMALL));  // "Hips"
  EXPECT_EQ(needed, 5u);
  for (char c : name) EXPECT_EQ(c, 'x');
  char text[16];
  std::memset(text, 'y', sizeof text);
  EXPECT_TRUE(Fails(mf_motion_save_bvh_to_memory(m.get(), nullptr, text, sizeof text, &needed),
                    MF_ERROR_BUFFER_TOO_SMALL));
  EXPECT_GT(needed, sizeof text);
  for (char c : text) EXPECT_EQ(c, 'y');

  mf_encoding* raw = nullptr;
  ASSERT_EQ(mf_encode(model.get(), m.get(), nullptr, &raw), MF_OK);
  const EncodingPtr code(raw);
  EXPECT_TRUE(Fails(mf_encoding_get_local_latents(raw, buffer.data(), 7, &needed), MF_ERROR_BUFFER_TOO_SMALL));
  EXPECT_EQ(needed, 8u);
  double times[1] = {-1.0};
  EXPECT_TRUE(Fails(mf_encoding_get_window_times(raw, times, 0, &needed), MF_ERROR_BUFFER_TOO_SMALL));
  EXPECT_EQ(times[0], -1.0);
  for (float v : buffer) ASSERT_EQ(v, -42.0f);
}

TEST(CApiBadInput, NonFiniteNumbers) {
  mf_motion* m = kMotionSentinel;
  {
    Arrays a;
    a.rotations[4 * 9 + 2] = kNaN;
    EXPECT_TRUE(Fails(a.create(&m), MF_ERROR_INVALID_ARGUMENT, "not a finite non-zero quaternion"));
  }
  {
    Arrays a;
    a.root[4] = kInf;
    EXPECT_TRUE(Fails(a.create(&m), MF_ERROR_INVALID_ARGUMENT, "root position of frame 1 is not finite"));
  }
  {
    Arrays a;
    a.offsets[5] = kNaN;
    EXPECT_TRUE(Fails(a.create(&m), MF_ERROR_INVALID_ARGUMENT, "non-finite offset"));
  }
  {
    Arrays a;
    for (int k = 0; k < 4; ++k) a.rotations[k] = 0.0f;  // a zero quaternion
    EXPECT_TRUE(Fails(a.create(&m), MF_ERROR_INVALID_ARGUMENT, "quaternion"));
  }
  const Arrays a;
  for (double fps : {0.0, -30.0, static_cast<double>(kNaN), static_cast<double>(kInf)}) {
    EXPECT_TRUE(Fails(mf_motion_create(7, a.name_ptrs.data(), a.parents.data(), a.offsets.data(), 5, fps,
                                       a.rotations.data(), a.root.data(), &m),
                      MF_ERROR_INVALID_ARGUMENT, "fps"));
  }
  EXPECT_EQ(m, kMotionSentinel);

  MotionPtr input;
  {
    mf_motion* raw = nullptr;
    ASSERT_EQ(a.create(&raw), MF_OK);
    input.reset(raw);
  }
  EXPECT_TRUE(Fails(mf_resample(nullptr, input.get(), kInf, nullptr, &m), MF_ERROR_INVALID_ARGUMENT, "fps"));
  EXPECT_TRUE(Fails(mf_resample(nullptr, input.get(), kNaN, nullptr, &m), MF_ERROR_INVALID_ARGUMENT, "fps"));
  int32_t n = 5;
  EXPECT_TRUE(Fails(mf_resample_frame_count(61, kNaN, 30.0, &n, nullptr), MF_ERROR_INVALID_ARGUMENT, "fps"));
  EXPECT_EQ(n, 5);
  mf_bvh_options bvh;
  mf_bvh_options_init(&bvh);
  bvh.length_scale = kNaN;
  EXPECT_TRUE(Fails(mf_motion_load_bvh(sample_bvh().c_str(), &bvh, &m), MF_ERROR_INVALID_ARGUMENT, "length_scale"));
  EXPECT_TRUE(Fails(mf_set_num_threads(-3), MF_ERROR_INVALID_ARGUMENT));

  const ModelPtr model = load_tiny_model();
  const MotionPtr walk = random_capi_motion(20, 30.0, 4);
  mf_encoding* raw = nullptr;
  ASSERT_EQ(mf_encode(model.get(), walk.get(), nullptr, &raw), MF_OK);
  const EncodingPtr code(raw);
  const double times[] = {0.1, std::numeric_limits<double>::quiet_NaN()};
  EXPECT_TRUE(Fails(mf_decode_times(raw, times, 2, 30.0, nullptr, &m), MF_ERROR_INVALID_ARGUMENT, "times[1]"));
  EXPECT_TRUE(Fails(mf_decode(raw, kNaN, 0, nullptr, &m), MF_ERROR_INVALID_ARGUMENT, "fps"));
  std::vector<float> z(8, 0.0f);
  z[3] = kInf;
  mf_encoding* e = kEncodingSentinel;
  EXPECT_TRUE(Fails(mf_encoding_with_latents(raw, z.data(), z.size(), nullptr, 0, &e), MF_ERROR_INVALID_ARGUMENT,
                    "not finite"));
  EXPECT_EQ(e, kEncodingSentinel);
  EXPECT_EQ(m, kMotionSentinel);
}

TEST(CApiBadInput, JointCountsThatDoNotMatch) {
  const ModelPtr model = load_tiny_model();
  const Arrays a;
  mf_motion* m = kMotionSentinel;
  EXPECT_TRUE(Fails(mf_motion_create_for_model(model.get(), 8, 5, 30.0, a.rotations.data(), a.root.data(), &m),
                    MF_ERROR_INVALID_ARGUMENT, "the model's skeleton has 7 joints"));
  const MotionPtr like = random_capi_motion(5, 30.0, 1);
  EXPECT_TRUE(Fails(mf_motion_create_like(like.get(), 6, 5, 30.0, a.rotations.data(), a.root.data(), &m),
                    MF_ERROR_INVALID_ARGUMENT, "7 joints"));
  EXPECT_TRUE(Fails(mf_motion_create(0, a.name_ptrs.data(), a.parents.data(), a.offsets.data(), 5, 30.0,
                                     a.rotations.data(), a.root.data(), &m),
                    MF_ERROR_INVALID_ARGUMENT, "joint_count"));
  EXPECT_EQ(m, kMotionSentinel);

  // The sample's 21 joints on the 7-joint model.
  mf_motion* raw = nullptr;
  ASSERT_EQ(mf_motion_load_bvh(sample_bvh().c_str(), nullptr, &raw), MF_OK);
  const MotionPtr walk(raw);
  mf_encoding* e = kEncodingSentinel;
  EXPECT_TRUE(Fails(mf_encode(model.get(), walk.get(), nullptr, &e), MF_ERROR_INVALID_ARGUMENT,
                    "the motion has 21 joints but the model's skeleton has 7"));
  EXPECT_EQ(e, kEncodingSentinel);
  for (const std::string& method : methods_with(MF_METHOD_NEEDS_MODEL | MF_METHOD_RESAMPLES)) {
    mf_task_options options;
    mf_task_options_init(&options);
    options.method = method.c_str();
    // Another rig than the model's: the tiny model has no rig anatomy to retarget with.
    EXPECT_TRUE(Fails(mf_resample(model.get(), walk.get(), 60.0, &options, &m), MF_ERROR_INVALID_ARGUMENT,
                      "the motion has 21 joints on another rig than the model's (7 joints), "
                      "and the model has no rig anatomy"));
  }
  EXPECT_EQ(m, kMotionSentinel);
}

TEST(CApiBadInput, FrameIndicesOutOfRange) {
  const MotionPtr input = random_capi_motion(61, 30.0, 3);
  mf_motion* m = kMotionSentinel;
  const int32_t past_end[] = {0, 30, 61};
  EXPECT_TRUE(Fails(mf_inbetween(nullptr, input.get(), past_end, 3, nullptr, &m), MF_ERROR_INVALID_ARGUMENT,
                    "keyframe 61 is out of range"));
  const int32_t negative[] = {-1, 30};
  EXPECT_TRUE(Fails(mf_inbetween(nullptr, input.get(), negative, 2, nullptr, &m), MF_ERROR_INVALID_ARGUMENT,
                    "keyframe -1 is out of range"));
  const int32_t unsorted[] = {0, 30, 20};
  EXPECT_TRUE(Fails(mf_inbetween(nullptr, input.get(), unsorted, 3, nullptr, &m), MF_ERROR_INVALID_ARGUMENT,
                    "increasing order"));
  EXPECT_TRUE(Fails(mf_inbetween(nullptr, input.get(), past_end, 1, nullptr, &m), MF_ERROR_INVALID_ARGUMENT,
                    "at least two keyframes"));
  EXPECT_TRUE(Fails(mf_fill(nullptr, input.get(), 0, 10, nullptr, &m), MF_ERROR_INVALID_ARGUMENT, "first frame"));
  EXPECT_TRUE(Fails(mf_fill(nullptr, input.get(), 10, 61, nullptr, &m), MF_ERROR_INVALID_ARGUMENT, "last frame"));
  EXPECT_TRUE(Fails(mf_fill(nullptr, input.get(), 20, 10, nullptr, &m), MF_ERROR_INVALID_ARGUMENT, "empty"));
  EXPECT_EQ(m, kMotionSentinel);

  char name[32] = "untouched";
  EXPECT_TRUE(Fails(mf_motion_get_joint_name(input.get(), 7, name, sizeof name, nullptr), MF_ERROR_INVALID_ARGUMENT,
                    "joint 7 is out of range"));
  EXPECT_TRUE(Fails(mf_motion_get_joint_name(input.get(), -1, name, sizeof name, nullptr), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_STREQ(name, "untouched");
  const char* method = "untouched";
  EXPECT_TRUE(Fails(mf_method_get(1000, &method, nullptr, nullptr), MF_ERROR_INVALID_ARGUMENT, "out of range"));
  EXPECT_TRUE(Fails(mf_method_get(-1, &method, nullptr, nullptr), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_STREQ(method, "untouched");
  const Arrays a;
  EXPECT_TRUE(Fails(mf_motion_create(7, a.name_ptrs.data(), a.parents.data(), a.offsets.data(), 0, 30.0,
                                     a.rotations.data(), a.root.data(), &m),
                    MF_ERROR_INVALID_ARGUMENT, "frame_count"));
  std::vector<int32_t> bad_parents = a.parents;
  bad_parents[2] = 5;  // a parent after its child
  EXPECT_TRUE(Fails(mf_motion_create(7, a.name_ptrs.data(), bad_parents.data(), a.offsets.data(), 5, 30.0,
                                     a.rotations.data(), a.root.data(), &m),
                    MF_ERROR_INVALID_ARGUMENT, "parents must come before their children"));
  EXPECT_EQ(m, kMotionSentinel);

  const ModelPtr model = load_tiny_model();
  mf_encoding* raw = nullptr;
  ASSERT_EQ(mf_encode(model.get(), input.get(), nullptr, &raw), MF_OK);
  const EncodingPtr code(raw);
  EXPECT_TRUE(Fails(mf_decode(raw, 30.0, -1, nullptr, &m), MF_ERROR_INVALID_ARGUMENT, "frame_count"));
  const double t = 0.0;
  EXPECT_TRUE(Fails(mf_decode_times(raw, &t, 0, 30.0, nullptr, &m), MF_ERROR_INVALID_ARGUMENT, "time_count"));
  mf_codec_options options;
  mf_codec_options_init(&options);
  options.hop = 32;  // no overlap
  mf_encoding* e = kEncodingSentinel;
  EXPECT_TRUE(Fails(mf_encode(model.get(), input.get(), &options, &e), MF_ERROR_INVALID_ARGUMENT));
  mf_codec_options_init(&options);
  options.root_source = 7;
  EXPECT_TRUE(Fails(mf_decode(raw, 30.0, 0, &options, &m), MF_ERROR_INVALID_ARGUMENT, "root_source"));
  std::vector<float> z(9, 0.0f);
  EXPECT_TRUE(Fails(mf_encoding_with_latents(raw, z.data(), z.size(), nullptr, 0, &e), MF_ERROR_INVALID_ARGUMENT,
                    "local_count is 9"));
  EXPECT_EQ(e, kEncodingSentinel);
  EXPECT_EQ(m, kMotionSentinel);
}

TEST(CApiBadInput, MethodsThatDoNotExistOrCannotRun) {
  const MotionPtr input = random_capi_motion(20, 30.0, 3);
  mf_task_options options;
  mf_task_options_init(&options);
  options.method = "magic";
  mf_motion* m = kMotionSentinel;
  const int32_t keys[] = {0, 19};
  EXPECT_TRUE(Fails(mf_inbetween(nullptr, input.get(), keys, 2, &options, &m), MF_ERROR_INVALID_ARGUMENT,
                    "unknown method 'magic' (available: interp, zerovel"));
  int32_t index = 99;
  EXPECT_TRUE(Fails(mf_method_find("magic", &index), MF_ERROR_INVALID_ARGUMENT, "unknown method 'magic'"));
  EXPECT_EQ(index, 99);
  for (const std::string& method : methods_with(MF_METHOD_NEEDS_MODEL)) {
    options.method = method.c_str();
    EXPECT_TRUE(Fails(mf_resample(nullptr, input.get(), 60.0, &options, &m), MF_ERROR_MODEL, "needs a model"));
    EXPECT_TRUE(Fails(mf_inbetween(nullptr, input.get(), keys, 2, &options, &m), MF_ERROR_MODEL, "needs a model"));
  }
  // A method without in-betweening (e.g. resampling only) says so.
  const ModelPtr model = load_tiny_model();
  for (const std::string& method : methods_with(MF_METHOD_RESAMPLES)) {
    int32_t i = 0;
    uint32_t flags = 0;
    ASSERT_EQ(mf_method_find(method.c_str(), &i), MF_OK);
    ASSERT_EQ(mf_method_get(i, nullptr, nullptr, &flags), MF_OK);
    if (flags & MF_METHOD_COMPLETES) continue;
    options.method = method.c_str();
    EXPECT_TRUE(Fails(mf_inbetween(model.get(), input.get(), keys, 2, &options, &m), MF_ERROR_INVALID_ARGUMENT,
                      "does not do in-betweening"));
  }
  EXPECT_EQ(m, kMotionSentinel);
}

TEST(CApiBadInput, OptionsFromOlderAndNewerCallers) {
  const MotionPtr input = random_capi_motion(20, 30.0, 3);
  const int32_t keys[] = {0, 10, 19};
  mf_motion* reference = nullptr;
  mf_task_options current;
  mf_task_options_init(&current);
  current.method = "zerovel";
  ASSERT_EQ(mf_inbetween(nullptr, input.get(), keys, 3, &current, &reference), MF_OK);
  const MotionPtr pref(reference);

  // An older caller's struct ends after `method`; what follows in memory is
  // garbage the library must not read (a progress pointer of all ones would crash).
  alignas(mf_task_options) unsigned char memory[sizeof(mf_task_options) + 16];
  std::memset(memory, 0xFF, sizeof memory);
  mf_task_options* old_struct = reinterpret_cast<mf_task_options*>(memory);
  old_struct->struct_size = offsetof(mf_task_options, method) + sizeof(const char*);
  old_struct->method = "zerovel";
  mf_motion* out = nullptr;
  ASSERT_EQ(mf_inbetween(nullptr, input.get(), keys, 3, old_struct, &out), MF_OK) << mf_last_error_message();
  const MotionPtr pout(out);
  EXPECT_EQ(rotations(out), rotations(reference));
  // Only struct_size: every option at its default.
  old_struct->struct_size = sizeof(uint32_t);
  ASSERT_EQ(mf_inbetween(nullptr, input.get(), keys, 3, old_struct, &out), MF_OK) << mf_last_error_message();
  mf_motion_destroy(out);

  // A newer caller's struct with an extra field: fine while it is zero.
  struct Newer {
    mf_task_options base;
    uint64_t future_field;
  } newer;
  std::memset(&newer, 0, sizeof newer);
  mf_task_options_init(&newer.base);
  newer.base.struct_size = sizeof newer;
  newer.base.method = "zerovel";
  ASSERT_EQ(mf_inbetween(nullptr, input.get(), keys, 3, &newer.base, &out), MF_OK) << mf_last_error_message();
  EXPECT_EQ(rotations(out), rotations(reference));
  mf_motion_destroy(out);
  newer.future_field = 1;
  out = kMotionSentinel;
  EXPECT_TRUE(Fails(mf_inbetween(nullptr, input.get(), keys, 3, &newer.base, &out), MF_ERROR_UNSUPPORTED,
                    "does not know"));
  EXPECT_EQ(out, kMotionSentinel);

  // A struct_size ending inside a pointer field (no published version does)
  // is refused: the library would otherwise read half of a non-NULL pointer.
  old_struct->struct_size = offsetof(mf_task_options, method) + 4;
  old_struct->method = "zerovel";
  out = kMotionSentinel;
  EXPECT_TRUE(Fails(mf_inbetween(nullptr, input.get(), keys, 3, old_struct, &out), MF_ERROR_INVALID_ARGUMENT,
                    "ends inside a pointer field (bytes 8 to 15)"));
  old_struct->struct_size = offsetof(mf_task_options, rig_map_path) + 1;
  EXPECT_TRUE(Fails(mf_inbetween(nullptr, input.get(), keys, 3, old_struct, &out), MF_ERROR_INVALID_ARGUMENT,
                    "ends inside a pointer field"));
  EXPECT_EQ(out, kMotionSentinel);
  // Ending after the last int32 field, before the struct's tail padding, is a real layout.
  mf_task_options padded;
  mf_task_options_init(&padded);
  padded.method = "zerovel";
  padded.struct_size = offsetof(mf_task_options, max_iterations) + sizeof(int32_t);
  ASSERT_EQ(mf_inbetween(nullptr, input.get(), keys, 3, &padded, &out), MF_OK) << mf_last_error_message();
  mf_motion_destroy(out);
  out = kMotionSentinel;

  // Uninitialised or absurd sizes.
  mf_task_options zero;
  std::memset(&zero, 0, sizeof zero);
  EXPECT_TRUE(Fails(mf_inbetween(nullptr, input.get(), keys, 3, &zero, &out), MF_ERROR_INVALID_ARGUMENT,
                    "mf_task_options_init"));
  zero.struct_size = 0xFFFFFFFFu;
  EXPECT_TRUE(Fails(mf_inbetween(nullptr, input.get(), keys, 3, &zero, &out), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_EQ(out, kMotionSentinel);

  // The same rules for the other options structs.
  mf_bvh_options bvh;
  std::memset(&bvh, 0, sizeof bvh);
  mf_motion* m = kMotionSentinel;
  EXPECT_TRUE(Fails(mf_motion_load_bvh(sample_bvh().c_str(), &bvh, &m), MF_ERROR_INVALID_ARGUMENT,
                    "mf_bvh_options_init"));
  bvh.struct_size = sizeof(uint32_t);  // older: length_scale unknown, so the default
  ASSERT_EQ(mf_motion_load_bvh(sample_bvh().c_str(), &bvh, &m), MF_OK);
  mf_motion_destroy(m);
  mf_codec_options codec;
  std::memset(&codec, 0, sizeof codec);
  codec.struct_size = offsetof(mf_codec_options, hop) + sizeof(int32_t);  // older: root_source unknown
  codec.root_source = 99;                                                 // ...and not read
  const ModelPtr model = load_tiny_model();
  mf_encoding* e = nullptr;
  ASSERT_EQ(mf_encode(model.get(), input.get(), &codec, &e), MF_OK) << mf_last_error_message();
  ASSERT_EQ(mf_decode(e, 30.0, 0, &codec, &m), MF_OK) << mf_last_error_message();
  mf_motion_destroy(m);
  mf_encoding_destroy(e);
}

TEST(CApiBadInput, FilesThatAreNotWhatTheyClaim) {
  const std::string dir = scratch();
  mf_model* model = kModelSentinel;
  EXPECT_TRUE(Fails(mf_model_load((dir + "/missing.mfm").c_str(), &model), MF_ERROR_IO, "cannot open"));
  EXPECT_TRUE(Fails(mf_model_load(dir.c_str(), &model), MF_ERROR_IO, "directory"));
  EXPECT_TRUE(Fails(mf_model_load("", &model), MF_ERROR_INVALID_ARGUMENT, "empty"));
  const std::string text = dir + "/text.mfm";
  write_file(text, "hello, I am not a model\n", 24);
  EXPECT_TRUE(Fails(mf_model_load(text.c_str(), &model), MF_ERROR_MODEL, "not a motionfield model file"));
  // The sample BVH is not a model either.
  EXPECT_TRUE(Fails(mf_model_load(sample_bvh().c_str(), &model), MF_ERROR_MODEL, "not a motionfield model file"));
  const std::vector<uint8_t>& bytes = tiny_model_bytes();
  const std::string truncated = dir + "/truncated.mfm";
  write_file(truncated, bytes.data(), bytes.size() / 2);
  EXPECT_TRUE(Fails(mf_model_load(truncated.c_str(), &model), MF_ERROR_MODEL, "truncated"));
  std::vector<uint8_t> corrupted = bytes;
  corrupted[corrupted.size() / 2] ^= 0x40;
  EXPECT_TRUE(Fails(mf_model_load_from_memory(corrupted.data(), corrupted.size(), &model), MF_ERROR_MODEL,
                    "checksum"));
  EXPECT_TRUE(Fails(mf_model_load_from_memory(bytes.data(), 0, &model), MF_ERROR_MODEL));
  EXPECT_TRUE(Fails(mf_model_load_from_memory(bytes.data(), 20, &model), MF_ERROR_MODEL));
  EXPECT_EQ(model, kModelSentinel);

  mf_motion* m = kMotionSentinel;
  EXPECT_TRUE(Fails(mf_motion_load_bvh((dir + "/missing.bvh").c_str(), nullptr, &m), MF_ERROR_IO, "cannot open"));
  EXPECT_TRUE(Fails(mf_motion_load_bvh(dir.c_str(), nullptr, &m), MF_ERROR_IO, "directory"));
  EXPECT_TRUE(Fails(mf_motion_load_bvh(tiny_model_path().c_str(), nullptr, &m), MF_ERROR_INVALID_ARGUMENT,
                    tiny_model_path() + ":"));
  const char garbage[] = "HIERARCHY\nROOT a\n{\n OFFSET 0 0 zero\n}\n";
  EXPECT_TRUE(Fails(mf_motion_load_bvh_from_memory(garbage, sizeof garbage - 1, nullptr, &m),
                    MF_ERROR_INVALID_ARGUMENT, "<memory>:"));
  EXPECT_TRUE(Fails(mf_motion_load_bvh_from_memory("", 0, nullptr, &m), MF_ERROR_INVALID_ARGUMENT));
  EXPECT_EQ(m, kMotionSentinel);

  const MotionPtr walk = random_capi_motion(5, 30.0, 1);
  EXPECT_TRUE(Fails(mf_motion_save_bvh(walk.get(), (dir + "/no/such/dir/out.bvh").c_str(), nullptr), MF_ERROR_IO,
                    "cannot write"));
  EXPECT_TRUE(Fails(mf_motion_save_bvh(walk.get(), "", nullptr), MF_ERROR_INVALID_ARGUMENT, "empty"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/no"));
  std::filesystem::remove_all(dir);
}

TEST(CApiBadInput, NoDefaultModel) {
  // A default path that does not exist: MF_MODEL names it.
  ASSERT_EQ(setenv("MF_MODEL", "/nonexistent/motionfield.mfm", 1), 0);
  mf_model* model = kModelSentinel;
  EXPECT_TRUE(Fails(mf_model_load(nullptr, &model), MF_ERROR_IO, "/nonexistent/motionfield.mfm"));
  EXPECT_EQ(model, kModelSentinel);
  unsetenv("MF_MODEL");
}

TEST(CApiBadInput, GltfOutput) {
  const std::string dir = scratch();
  const MotionPtr walk = random_capi_motion(5, 30.0, 1);
  mf_gltf_options o;
  ASSERT_EQ(mf_gltf_options_init(&o), MF_OK);
  EXPECT_TRUE(Fails(mf_gltf_options_init(nullptr), MF_ERROR_INVALID_ARGUMENT, "options"));
  EXPECT_TRUE(Fails(mf_motion_save_gltf(nullptr, (dir + "/a.glb").c_str(), &o), MF_ERROR_INVALID_ARGUMENT, "motion"));
  EXPECT_TRUE(Fails(mf_motion_save_gltf(walk.get(), nullptr, &o), MF_ERROR_INVALID_ARGUMENT, "path"));
  EXPECT_TRUE(Fails(mf_motion_save_gltf(walk.get(), "", &o), MF_ERROR_INVALID_ARGUMENT, "empty"));
  // Unwritable: a missing directory, a directory, a read-only directory (unless root).
  EXPECT_TRUE(Fails(mf_motion_save_gltf(walk.get(), (dir + "/no/such/dir/out.glb").c_str(), &o), MF_ERROR_IO,
                    "cannot write " + dir + "/no/such/dir/out.glb"));
  std::filesystem::create_directories(dir + "/d.glb");
  EXPECT_TRUE(Fails(mf_motion_save_gltf(walk.get(), (dir + "/d.glb").c_str(), &o), MF_ERROR_IO, "cannot write"));
  // The format: not from an unknown extension, not an unknown value, not an uninitialised struct.
  EXPECT_TRUE(Fails(mf_motion_save_gltf(walk.get(), (dir + "/out.bvh").c_str(), &o), MF_ERROR_INVALID_ARGUMENT,
                    ".glb"));
  mf_gltf_options bad = o;
  bad.format = 7;
  EXPECT_TRUE(Fails(mf_motion_save_gltf(walk.get(), (dir + "/out.glb").c_str(), &bad), MF_ERROR_INVALID_ARGUMENT,
                    "MF_GLTF_BINARY"));
  bad = o;
  bad.struct_size = 0;
  EXPECT_TRUE(Fails(mf_motion_save_gltf(walk.get(), (dir + "/out.glb").c_str(), &bad), MF_ERROR_INVALID_ARGUMENT,
                    "mf_gltf_options_init"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/out.glb"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/out.bvh"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/no"));
  // To memory: a size query needs `needed`; a short buffer is untouched.
  EXPECT_TRUE(Fails(mf_motion_save_gltf_to_memory(walk.get(), nullptr, nullptr, 0, nullptr),
                    MF_ERROR_INVALID_ARGUMENT, "needed"));
  size_t needed = 0;
  ASSERT_EQ(mf_motion_save_gltf_to_memory(walk.get(), nullptr, nullptr, 0, &needed), MF_OK);
  std::vector<uint8_t> small(needed - 1, 0xab);
  size_t told = 0;
  EXPECT_TRUE(Fails(mf_motion_save_gltf_to_memory(walk.get(), nullptr, small.data(), small.size(), &told),
                    MF_ERROR_BUFFER_TOO_SMALL));
  EXPECT_EQ(told, needed);
  EXPECT_EQ(small, std::vector<uint8_t>(needed - 1, 0xab));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mf::capi_test
