// The C API's behaviour on good input: versions, methods, models, motions
// (arrays and BVH), tasks, progress and cancel, threads, encode and decode.
#include <dlfcn.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <unistd.h>

#include "tests/capi/capi_test_util.h"
#include "tests/test_util.h"

namespace mf::capi_test {
namespace {

MotionPtr load_sample() {
  mf_motion* m = nullptr;
  const int status = mf_motion_load_bvh(sample_bvh().c_str(), nullptr, &m);
  EXPECT_EQ(status, MF_OK) << describe(status);
  return MotionPtr(m);
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string hierarchy_of(const std::string& bvh) { return bvh.substr(0, bvh.find("MOTION")); }

TEST(CApi, VersionsAgreeWithTheHeaderAndTheProject) {
  EXPECT_EQ(mf_abi_version(), static_cast<uint32_t>(MF_ABI_VERSION));
  EXPECT_EQ(mf_version_number(), static_cast<uint32_t>(MF_VERSION_NUMBER));
  EXPECT_STREQ(mf_version_string(), MF_VERSION_STRING);
  EXPECT_STREQ(mf_version_string(), MF_PROJECT_VERSION);
  EXPECT_EQ(std::to_string(MF_VERSION_MAJOR) + "." + std::to_string(MF_VERSION_MINOR) + "." +
                std::to_string(MF_VERSION_PATCH),
            MF_VERSION_STRING);
}

TEST(CApi, StatusNamesAndTheMessageIsNeverNull) {
  std::thread([] { EXPECT_STREQ(mf_last_error_message(), ""); }).join();  // a fresh thread: no error yet
  EXPECT_STREQ(mf_status_name(MF_OK), "MF_OK");
  EXPECT_STREQ(mf_status_name(MF_ERROR_INVALID_ARGUMENT), "MF_ERROR_INVALID_ARGUMENT");
  EXPECT_STREQ(mf_status_name(MF_ERROR_OUT_OF_MEMORY), "MF_ERROR_OUT_OF_MEMORY");
  EXPECT_STREQ(mf_status_name(12345), "MF_ERROR_UNKNOWN");
  ASSERT_EQ(mf_set_num_threads(0), MF_ERROR_INVALID_ARGUMENT);
  const std::string message = mf_last_error_message();
  EXPECT_NE(message.find("between 1 and 1024"), std::string::npos) << message;
  // Successful calls leave the message; it is per thread.
  int32_t n = 0;
  EXPECT_EQ(mf_method_count(&n), MF_OK);
  EXPECT_EQ(mf_last_error_message(), message);
  std::thread([] { EXPECT_STREQ(mf_last_error_message(), ""); }).join();
}

// Until mf_set_num_threads is called a task runs on one thread, its calling
// thread, and OpenBLAS's own pool (one thread per core unless told otherwise)
// is held at one thread: left alone, it made a default caller's in-between
// about 10x slower on a busy machine. CTest runs each test in a process of its
// own, so this sees the fresh state (OpenBLAS's pool as it loaded: a thread
// per core).
TEST(CApi, WithoutAThreadCountTasksRunOnOneThreadAndBlasStaysSerial) {
  int32_t n = 0;
  ASSERT_EQ(mf_get_num_threads(&n), MF_OK);  // library work without a chosen count
  EXPECT_EQ(n, 1);
  int32_t other = 0;  // so does a task on any other thread
  std::thread([&] { EXPECT_EQ(mf_get_num_threads(&other), MF_OK); }).join();
  EXPECT_EQ(other, 1);
  using GetThreads = int (*)();
  auto openblas = reinterpret_cast<GetThreads>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  if (!openblas) GTEST_SKIP() << "the BLAS is not OpenBLAS";
  EXPECT_EQ(openblas(), 1);
}

TEST(CApi, ThreadCount) {
  ASSERT_EQ(mf_set_num_threads(1), MF_OK);
  int32_t n = 0;
  ASSERT_EQ(mf_get_num_threads(&n), MF_OK);
  EXPECT_EQ(n, 1);
  // Another thread sees the same setting once it runs library work.
  std::thread([] {
    int32_t m = 0;
    EXPECT_EQ(mf_get_num_threads(&m), MF_OK);
    EXPECT_EQ(m, 1);
  }).join();
}

TEST(CApi, MethodsAreListedWithTheirFlags) {
  int32_t count = 0;
  ASSERT_EQ(mf_method_count(&count), MF_OK);
  ASSERT_GE(count, 2);
  for (const char* baseline : {"interp", "zerovel"}) {
    int32_t index = -1;
    ASSERT_EQ(mf_method_find(baseline, &index), MF_OK);
    const char* name = nullptr;
    const char* description = nullptr;
    uint32_t flags = 0;
    ASSERT_EQ(mf_method_get(index, &name, &description, &flags), MF_OK);
    EXPECT_STREQ(name, baseline);
    EXPECT_GT(std::strlen(description), 0u);
    EXPECT_EQ(flags, MF_METHOD_COMPLETES | MF_METHOD_RESAMPLES);
  }
  const char* def = nullptr;
  ASSERT_EQ(mf_default_method(nullptr, &def), MF_OK);
  int32_t index = -1;
  ASSERT_EQ(mf_method_find(def, &index), MF_OK);
  uint32_t flags = 0;
  ASSERT_EQ(mf_method_get(index, nullptr, nullptr, &flags), MF_OK);
  EXPECT_EQ(flags & MF_METHOD_NEEDS_MODEL, 0u) << "without a model the default needs none: " << def;
  const ModelPtr model = load_tiny_model();
  ASSERT_EQ(mf_default_method(model.get(), &def), MF_OK);
  EXPECT_EQ(mf_method_find(def, &index), MF_OK);
}

TEST(CApi, ModelQueries) {
  const ModelPtr model = load_tiny_model();
  ASSERT_TRUE(model);
  const Skeleton s = test::small_skeleton();
  int32_t joints = 0, window = 0, zl = 0, zg = 0;
  double fps = 0;
  ASSERT_EQ(mf_model_get_joint_count(model.get(), &joints), MF_OK);
  EXPECT_EQ(joints, s.num_joints());
  ASSERT_EQ(mf_model_get_fps(model.get(), &fps), MF_OK);
  EXPECT_EQ(fps, 30.0);
  ASSERT_EQ(mf_model_get_window(model.get(), &window), MF_OK);
  EXPECT_EQ(window, 32);
  ASSERT_EQ(mf_model_get_latent_sizes(model.get(), &zl, &zg), MF_OK);
  EXPECT_EQ(zl, 8);
  EXPECT_EQ(zg, 4);
  for (int j = 0; j < joints; ++j) {
    char name[64];
    size_t needed = 0;
    ASSERT_EQ(mf_model_get_joint_name(model.get(), j, name, sizeof name, &needed), MF_OK);
    EXPECT_EQ(name, s.names[j]);
    EXPECT_EQ(needed, s.names[j].size() + 1);
  }
  std::vector<int32_t> parents(joints);
  ASSERT_EQ(mf_model_get_parents(model.get(), parents.data(), parents.size(), nullptr), MF_OK);
  EXPECT_EQ(std::vector<int>(parents.begin(), parents.end()), s.parents);
  size_t needed = 0;
  ASSERT_EQ(mf_model_get_offsets(model.get(), nullptr, 0, &needed), MF_OK);
  ASSERT_EQ(needed, static_cast<size_t>(3 * joints));
  std::vector<float> offsets(needed);
  ASSERT_EQ(mf_model_get_offsets(model.get(), offsets.data(), offsets.size(), &needed), MF_OK);
  for (int j = 0; j < joints; ++j)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(offsets[3 * j + k], static_cast<float>(s.offsets[j][k]));

  // From memory: the same model.
  mf_model* from_memory = nullptr;
  ASSERT_EQ(mf_model_load_from_memory(tiny_model_bytes().data(), tiny_model_bytes().size(), &from_memory), MF_OK);
  const ModelPtr owned(from_memory);
  int32_t joints2 = 0;
  ASSERT_EQ(mf_model_get_joint_count(from_memory, &joints2), MF_OK);
  EXPECT_EQ(joints2, joints);
}

TEST(CApi, DefaultModelPathAndLoad) {
  size_t needed = 0;
  ASSERT_EQ(mf_model_default_path(nullptr, 0, &needed), MF_OK);
  ASSERT_GE(needed, 1u);
  std::string path(needed, '\0');
  ASSERT_EQ(mf_model_default_path(path.data(), path.size(), &needed), MF_OK);
  path.resize(needed - 1);
  // $MF_MODEL wins.
  ASSERT_EQ(setenv("MF_MODEL", tiny_model_path().c_str(), 1), 0);
  char buffer[4096];
  ASSERT_EQ(mf_model_default_path(buffer, sizeof buffer, &needed), MF_OK);
  EXPECT_EQ(std::string(buffer), tiny_model_path());
  mf_model* model = nullptr;
  ASSERT_EQ(mf_model_load(nullptr, &model), MF_OK) << describe(MF_ERROR_MODEL);
  mf_model_destroy(model);
  unsetenv("MF_MODEL");
}

TEST(CApi, MotionFromArraysRoundTripsExactly) {
  const Motion cpp = test::random_motion(test::small_skeleton(), 20, 24.0, 7);
  const MotionPtr m = to_capi(cpp);
  ASSERT_TRUE(m);
  int32_t joints = 0;
  double fps = 0, frame_time = 0;
  ASSERT_EQ(mf_motion_get_joint_count(m.get(), &joints), MF_OK);
  EXPECT_EQ(joints, 7);
  EXPECT_EQ(frame_count(m.get()), 20);
  ASSERT_EQ(mf_motion_get_fps(m.get(), &fps), MF_OK);
  EXPECT_EQ(fps, 24.0);
  ASSERT_EQ(mf_motion_get_frame_time(m.get(), &frame_time), MF_OK);
  EXPECT_EQ(frame_time, 1.0 / 24.0);
  const std::vector<float> rot = rotations(m.get());
  ASSERT_EQ(rot.size(), 20u * 7 * 4);
  for (size_t i = 0; i < cpp.rotations.size(); ++i) {
    EXPECT_EQ(rot[4 * i], static_cast<float>(cpp.rotations[i].w()));
    EXPECT_EQ(rot[4 * i + 3], static_cast<float>(cpp.rotations[i].z()));
  }
  const std::vector<float> root = root_positions(m.get());
  ASSERT_EQ(root.size(), 60u);
  EXPECT_EQ(root[3 * 5 + 1], static_cast<float>(cpp.root_positions[5].y()));

  // The same arrays on the model's skeleton and "like" this motion.
  const ModelPtr model = load_tiny_model();
  mf_motion* a = nullptr;
  ASSERT_EQ(mf_motion_create_for_model(model.get(), 7, 20, 24.0, rot.data(), root.data(), &a), MF_OK);
  const MotionPtr pa(a);
  EXPECT_EQ(rotations(a), rot);
  mf_motion* b = nullptr;
  ASSERT_EQ(mf_motion_create_like(m.get(), 7, 20, 24.0, rot.data(), root.data(), &b), MF_OK);
  const MotionPtr pb(b);
  EXPECT_EQ(root_positions(b), root);

  // Global positions: the root joint is the root position.
  size_t needed = 0;
  ASSERT_EQ(mf_motion_get_global_positions(m.get(), nullptr, 0, &needed), MF_OK);
  ASSERT_EQ(needed, 20u * 7 * 3);
  std::vector<float> global(needed);
  ASSERT_EQ(mf_motion_get_global_positions(m.get(), global.data(), global.size(), &needed), MF_OK);
  EXPECT_NEAR(global[3 * 7 * 4 + 0], root[3 * 4 + 0], 1e-6);
  EXPECT_NEAR(global[3 * 7 * 4 + 2], root[3 * 4 + 2], 1e-6);
}

TEST(CApi, BvhKeepsItsLayoutAndFrameTime) {
  const MotionPtr m = load_sample();
  ASSERT_TRUE(m);
  int32_t joints = 0;
  double fps = 0, frame_time = 0;
  ASSERT_EQ(mf_motion_get_joint_count(m.get(), &joints), MF_OK);
  EXPECT_EQ(joints, 21);  // 22 in the file: the container root is folded into Hips
  EXPECT_EQ(frame_count(m.get()), 61);
  ASSERT_EQ(mf_motion_get_fps(m.get(), &fps), MF_OK);
  EXPECT_EQ(fps, 30.0);
  ASSERT_EQ(mf_motion_get_frame_time(m.get(), &frame_time), MF_OK);
  EXPECT_EQ(frame_time, 0.0333333333);  // as written in the file
  char name[64];
  ASSERT_EQ(mf_motion_get_joint_name(m.get(), 0, name, sizeof name, nullptr), MF_OK);
  EXPECT_STREQ(name, "Hips");

  // Text through memory: same hierarchy, same frame time line.
  size_t needed = 0;
  ASSERT_EQ(mf_motion_save_bvh_to_memory(m.get(), nullptr, nullptr, 0, &needed), MF_OK);
  std::string text(needed, '\0');
  ASSERT_EQ(mf_motion_save_bvh_to_memory(m.get(), nullptr, text.data(), text.size(), &needed), MF_OK);
  text.resize(needed - 1);
  const std::string original = read_file(sample_bvh());
  EXPECT_EQ(hierarchy_of(text), hierarchy_of(original));
  EXPECT_NE(text.find("Frame Time: 0.0333333333"), std::string::npos);
  mf_motion* back = nullptr;
  ASSERT_EQ(mf_motion_load_bvh_from_memory(text.data(), text.size(), nullptr, &back), MF_OK);
  const MotionPtr pback(back);
  const std::vector<float> r0 = rotations(m.get()), r1 = rotations(back);
  ASSERT_EQ(r0.size(), r1.size());
  for (size_t i = 0; i < r0.size(); ++i) ASSERT_NEAR(r0[i], r1[i], 1e-6);

  // A file, and the length scale: metres in the file are 100 times smaller.
  const std::string dir = test::scratch_dir("capi-bvh-" + std::to_string(::getpid()));
  const std::string path = dir + "/out.bvh";
  ASSERT_EQ(mf_motion_save_bvh(m.get(), path.c_str(), nullptr), MF_OK);
  EXPECT_EQ(read_file(path), text);
  mf_bvh_options metres;
  ASSERT_EQ(mf_bvh_options_init(&metres), MF_OK);
  EXPECT_EQ(metres.struct_size, sizeof metres);
  EXPECT_EQ(metres.length_scale, 0.0);
  metres.length_scale = 1.0;
  mf_motion* big = nullptr;
  ASSERT_EQ(mf_motion_load_bvh(path.c_str(), &metres, &big), MF_OK);
  const MotionPtr pbig(big);
  EXPECT_NEAR(root_positions(big)[1], 100.0f * root_positions(m.get())[1], 1e-3);
  std::filesystem::remove_all(dir);
}

TEST(CApi, MotionsFromArraysGetADefaultLayout) {
  const MotionPtr m = random_capi_motion(10, 30.0, 1);
  size_t needed = 0;
  ASSERT_EQ(mf_motion_save_bvh_to_memory(m.get(), nullptr, nullptr, 0, &needed), MF_OK);
  std::string text(needed, '\0');
  ASSERT_EQ(mf_motion_save_bvh_to_memory(m.get(), nullptr, text.data(), text.size(), &needed), MF_OK);
  EXPECT_NE(text.find("ROOT Hips"), std::string::npos);
  EXPECT_NE(text.find("Frames: 10"), std::string::npos);
  mf_motion* back = nullptr;
  ASSERT_EQ(mf_motion_load_bvh_from_memory(text.data(), needed - 1, nullptr, &back), MF_OK);
  const MotionPtr pback(back);
  const std::vector<float> a = root_positions(m.get()), b = root_positions(back);
  for (size_t i = 0; i < a.size(); ++i) ASSERT_NEAR(a[i], b[i], 1e-6);
}

TEST(CApi, InbetweenFillAndResampleWithBaselines) {
  const MotionPtr input = load_sample();
  const std::vector<float> r_in = rotations(input.get()), p_in = root_positions(input.get());
  const int J = 21;
  mf_task_options options;
  ASSERT_EQ(mf_task_options_init(&options), MF_OK);
  EXPECT_EQ(options.struct_size, sizeof options);
  EXPECT_EQ(options.method, nullptr);
  const int32_t keys[] = {0, 20, 40, 60};
  for (const char* method : {"interp", "zerovel"}) {
    options.method = method;
    mf_motion* out = nullptr;
    ASSERT_EQ(mf_inbetween(nullptr, input.get(), keys, 4, &options, &out), MF_OK) << describe(MF_OK);
    const MotionPtr result(out);
    ASSERT_EQ(frame_count(out), 61);
    const std::vector<float> r = rotations(out);
    for (int32_t k : keys)
      for (int i = 0; i < 4 * J; ++i) ASSERT_EQ(r[4 * J * k + i], r_in[4 * J * k + i]) << method << " frame " << k;
    EXPECT_NE(r[4 * J * 10 + 4 * 3], r_in[4 * J * 10 + 4 * 3]) << method;  // an unknown frame changed
  }
  // The default method is the one mf_default_method names.
  const char* def = nullptr;
  ASSERT_EQ(mf_default_method(nullptr, &def), MF_OK);
  options.method = def;
  mf_motion* named = nullptr;
  ASSERT_EQ(mf_inbetween(nullptr, input.get(), keys, 4, &options, &named), MF_OK);
  const MotionPtr pnamed(named);
  mf_motion* defaulted = nullptr;
  ASSERT_EQ(mf_inbetween(nullptr, input.get(), keys, 4, nullptr, &defaulted), MF_OK);
  const MotionPtr pdefaulted(defaulted);
  EXPECT_EQ(rotations(named), rotations(defaulted));

  mf_motion* filled = nullptr;
  ASSERT_EQ(mf_fill(nullptr, input.get(), 10, 40, nullptr, &filled), MF_OK);
  const MotionPtr pfilled(filled);
  const std::vector<float> pf = root_positions(filled);
  for (int f : {0, 9, 40, 60})
    for (int k = 0; k < 3; ++k) EXPECT_EQ(pf[3 * f + k], p_in[3 * f + k]);

  mf_motion* up = nullptr;
  ASSERT_EQ(mf_resample(nullptr, input.get(), 60.0, nullptr, &up), MF_OK);
  const MotionPtr pup(up);
  EXPECT_EQ(frame_count(up), 121);
  double fps = 0, frame_time = 0;
  ASSERT_EQ(mf_motion_get_fps(up, &fps), MF_OK);
  EXPECT_EQ(fps, 60.0);
  ASSERT_EQ(mf_motion_get_frame_time(up, &frame_time), MF_OK);
  EXPECT_EQ(frame_time, 1.0 / 60.0);
  const std::vector<float> pu = root_positions(up);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(pu[3 * 2 * 7 + k], p_in[3 * 7 + k]);  // input frame 7 = output frame 14

  int32_t n = 0, rounded = -1;
  ASSERT_EQ(mf_resample_frame_count(61, 30.0, 23.3, &n, &rounded), MF_OK);
  EXPECT_EQ(n, 47);
  EXPECT_EQ(rounded, 1);
  ASSERT_EQ(mf_resample_frame_count(61, 1.0 / 0.0333333, 60.0, &n, &rounded), MF_OK);
  EXPECT_EQ(n, 121);
  EXPECT_EQ(rounded, 0);
}

std::string warnings_of(const mf_motion* m) {
  size_t n = 0;
  EXPECT_EQ(mf_motion_get_warnings(m, nullptr, 0, &n), MF_OK);
  std::string text(n, '\0');
  EXPECT_EQ(mf_motion_get_warnings(m, text.data(), text.size(), &n), MF_OK);
  text.resize(n - 1);
  return text;
}

TEST(CApi, ResampleWarnsWhenItRoundsTheFrameCountDown) {
  const MotionPtr input = load_sample();
  EXPECT_EQ(warnings_of(input.get()), "");  // not made by a task
  mf_motion* exact = nullptr;
  ASSERT_EQ(mf_resample(nullptr, input.get(), 60.0, nullptr, &exact), MF_OK);
  const MotionPtr pexact(exact);
  EXPECT_EQ(warnings_of(exact), "");
  mf_motion* rounded = nullptr;
  ASSERT_EQ(mf_resample(nullptr, input.get(), 23.3, nullptr, &rounded), MF_OK);
  const MotionPtr prounded(rounded);
  EXPECT_EQ(frame_count(rounded), 47);
  const std::string w = warnings_of(rounded);
  EXPECT_NE(w.find("resampling 61 frames from 30 to 23.3 fps"), std::string::npos) << w;
  EXPECT_NE(w.find("rounded down to 47 frames"), std::string::npos) << w;
  EXPECT_EQ(w.find('\n'), std::string::npos) << "one warning, one line: " << w;
  // A motion derived from it (same skeleton, new values) starts without warnings.
  const std::vector<float> rot = rotations(rounded), pos = root_positions(rounded);
  int32_t joints = 0;
  ASSERT_EQ(mf_motion_get_joint_count(rounded, &joints), MF_OK);
  mf_motion* like = nullptr;
  ASSERT_EQ(mf_motion_create_like(rounded, joints, 47, 23.3, rot.data(), pos.data(), &like), MF_OK);
  const MotionPtr plike(like);
  EXPECT_EQ(warnings_of(like), "");
  size_t needed = 0;
  char small[4];
  EXPECT_EQ(mf_motion_get_warnings(rounded, small, sizeof small, &needed), MF_ERROR_BUFFER_TOO_SMALL);
  EXPECT_EQ(needed, w.size() + 1);
  EXPECT_EQ(mf_motion_get_warnings(nullptr, small, sizeof small, &needed), MF_ERROR_INVALID_ARGUMENT);
}

TEST(CApi, TaskResultsKeepTheInputsLayout) {
  const MotionPtr input = load_sample();
  mf_motion* out = nullptr;
  const int32_t keys[] = {0, 60};
  ASSERT_EQ(mf_inbetween(nullptr, input.get(), keys, 2, nullptr, &out), MF_OK);
  const MotionPtr result(out);
  size_t needed = 0;
  ASSERT_EQ(mf_motion_save_bvh_to_memory(out, nullptr, nullptr, 0, &needed), MF_OK);
  std::string text(needed, '\0');
  ASSERT_EQ(mf_motion_save_bvh_to_memory(out, nullptr, text.data(), text.size(), &needed), MF_OK);
  EXPECT_EQ(hierarchy_of(text), hierarchy_of(read_file(sample_bvh())));
  EXPECT_NE(text.find("Frame Time: 0.0333333333"), std::string::npos);
}

struct ProgressLog {
  int calls = 0;
  uint32_t struct_size = 0;
  int cancel_at = -1;  // cancel on this call (0-based), -1 never
};

int log_progress(void* user_data, const mf_progress* p) {
  auto* log = static_cast<ProgressLog*>(user_data);
  log->struct_size = p->struct_size;
  return log->calls++ == log->cancel_at ? 1 : 0;
}

TEST(CApi, ProgressCallbackAndCancelToken) {
  const MotionPtr input = load_sample();
  const int32_t keys[] = {0, 30, 60};
  ProgressLog log;
  mf_task_options options;
  mf_task_options_init(&options);
  options.progress = log_progress;
  options.user_data = &log;
  mf_motion* out = nullptr;
  ASSERT_EQ(mf_inbetween(nullptr, input.get(), keys, 3, &options, &out), MF_OK);
  mf_motion_destroy(out);
  EXPECT_GE(log.calls, 1);
  EXPECT_EQ(log.struct_size, sizeof(mf_progress));

  // A callback returning non-zero cancels; nothing is produced.
  log = ProgressLog{};
  log.cancel_at = 0;
  out = reinterpret_cast<mf_motion*>(0x1234);
  EXPECT_EQ(mf_inbetween(nullptr, input.get(), keys, 3, &options, &out), MF_ERROR_CANCELLED);
  EXPECT_EQ(out, reinterpret_cast<mf_motion*>(0x1234));
  EXPECT_STREQ(mf_last_error_message(), "cancelled");

  // A token cancelled before the call; then reset.
  mf_cancel_token* raw = nullptr;
  ASSERT_EQ(mf_cancel_token_create(&raw), MF_OK);
  const TokenPtr token(raw);
  mf_task_options_init(&options);
  options.cancel = raw;
  int32_t cancelled = -1;
  ASSERT_EQ(mf_cancel_token_is_cancelled(raw, &cancelled), MF_OK);
  EXPECT_EQ(cancelled, 0);
  ASSERT_EQ(mf_cancel_token_cancel(raw), MF_OK);
  ASSERT_EQ(mf_cancel_token_is_cancelled(raw, &cancelled), MF_OK);
  EXPECT_EQ(cancelled, 1);
  EXPECT_EQ(mf_resample(nullptr, input.get(), 60.0, &options, &out), MF_ERROR_CANCELLED);
  ASSERT_EQ(mf_cancel_token_reset(raw), MF_OK);
  out = nullptr;
  ASSERT_EQ(mf_resample(nullptr, input.get(), 60.0, &options, &out), MF_OK);
  mf_motion_destroy(out);
}

// A solver that reports progress, cancelled from another thread while it runs:
// the third progress call waits until the other thread has cancelled the token,
// so the cancel always lands in the middle of the solve.
TEST(CApi, CancelFromAnotherThreadStopsASolver) {
  const std::vector<std::string> solvers = methods_with(MF_METHOD_NEEDS_MODEL | MF_METHOD_COMPLETES);
  ASSERT_FALSE(solvers.empty()) << "no registered method solves with the prior";
  const ModelPtr model = load_tiny_model();
  const MotionPtr input = random_capi_motion(30, 30.0, 5);  // within one window of the tiny model
  mf_cancel_token* raw = nullptr;
  ASSERT_EQ(mf_cancel_token_create(&raw), MF_OK);
  const TokenPtr token(raw);
  struct Rendezvous {
    std::atomic<int> calls{0};
    std::atomic<bool> asked{false}, cancelled{false};
  } rv;
  mf_task_options options;
  mf_task_options_init(&options);
  options.method = solvers.front().c_str();
  options.cancel = raw;
  options.user_data = &rv;
  options.progress = [](void* user_data, const mf_progress*) {
    auto* r = static_cast<Rendezvous*>(user_data);
    if (++r->calls == 3) {
      r->asked = true;
      while (!r->cancelled.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return 0;
  };
  int status = -1;
  mf_motion* out = reinterpret_cast<mf_motion*>(0x1234);
  std::thread solver([&] {
    const int32_t keys[] = {0, 29};
    status = mf_inbetween(model.get(), input.get(), keys, 2, &options, &out);
  });
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!rv.asked.load() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const bool reached = rv.asked.load();
  EXPECT_EQ(mf_cancel_token_cancel(raw), MF_OK);
  rv.cancelled = true;
  solver.join();
  const MotionPtr produced(status == MF_OK ? out : nullptr);
  ASSERT_TRUE(reached) << solvers.front() << " made " << rv.calls.load() << " progress calls, expected at least 3";
  EXPECT_EQ(status, MF_ERROR_CANCELLED) << describe(status);
  EXPECT_EQ(out, reinterpret_cast<mf_motion*>(0x1234)) << "a cancelled task produced a motion";
  EXPECT_EQ(rv.calls.load(), 3) << "the solve went on after the cancel";
}

// mf_task_options.max_iterations: the solver's iteration budget. The progress
// reports show it (max_iterations) and the solve stays within it; negative
// budgets are refused.
TEST(CApi, MaxIterationsBudgetsTheSolver) {
  const std::vector<std::string> solvers = methods_with(MF_METHOD_NEEDS_MODEL | MF_METHOD_COMPLETES);
  ASSERT_FALSE(solvers.empty());
  const ModelPtr model = load_tiny_model();
  const MotionPtr input = random_capi_motion(30, 30.0, 5);
  struct Seen {
    int32_t iteration = 0, max_iterations = 0;
  };
  const auto solve = [&](int32_t budget, Seen* seen) {
    mf_task_options options;
    mf_task_options_init(&options);
    EXPECT_EQ(options.max_iterations, 0);
    options.method = "nemf";
    options.max_iterations = budget;
    options.user_data = seen;
    options.progress = [](void* user_data, const mf_progress* p) {
      auto* s = static_cast<Seen*>(user_data);
      s->iteration = std::max(s->iteration, p->iteration);
      s->max_iterations = std::max(s->max_iterations, p->max_iterations);
      return 0;
    };
    const int32_t keys[] = {0, 29};
    mf_motion* out = nullptr;
    const int status = mf_inbetween(model.get(), input.get(), keys, 2, &options, &out);
    mf_motion_destroy(out);
    return status;
  };
  Seen by_default, budgeted, refused;
  ASSERT_EQ(solve(0, &by_default), MF_OK) << mf_last_error_message();
  ASSERT_EQ(solve(2, &budgeted), MF_OK) << mf_last_error_message();
  EXPECT_LT(budgeted.max_iterations, by_default.max_iterations);
  EXPECT_LE(budgeted.iteration, budgeted.max_iterations);
  EXPECT_EQ(solve(-1, &refused), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(mf_last_error_message()).find("max_iterations"), std::string::npos) << mf_last_error_message();
}

TEST(CApi, EncodeAndDecodeAtAnyTimes) {
  const ModelPtr model = load_tiny_model();
  const MotionPtr input = random_capi_motion(70, 30.0, 11);
  mf_encoding* raw = nullptr;
  ASSERT_EQ(mf_encode(model.get(), input.get(), nullptr, &raw), MF_OK) << describe(MF_OK);
  const EncodingPtr code(raw);
  int32_t windows = 0;
  ASSERT_EQ(mf_encoding_get_window_count(raw, &windows), MF_OK);
  EXPECT_EQ(windows, 4);  // 70 frames, window 32, hop 16: starts 0, 16, 32, 38
  double duration = 0;
  ASSERT_EQ(mf_encoding_get_duration(raw, &duration), MF_OK);
  EXPECT_DOUBLE_EQ(duration, 69 / 30.0);
  std::vector<double> starts(windows);
  ASSERT_EQ(mf_encoding_get_window_times(raw, starts.data(), starts.size(), nullptr), MF_OK);
  EXPECT_DOUBLE_EQ(starts[1], 16 / 30.0);
  EXPECT_DOUBLE_EQ(starts[3], 38 / 30.0);
  size_t nl = 0, ng = 0;
  ASSERT_EQ(mf_encoding_get_local_latents(raw, nullptr, 0, &nl), MF_OK);
  ASSERT_EQ(mf_encoding_get_global_latents(raw, nullptr, 0, &ng), MF_OK);
  EXPECT_EQ(nl, static_cast<size_t>(windows) * 8);
  EXPECT_EQ(ng, static_cast<size_t>(windows) * 4);
  std::vector<float> zl(nl), zg(ng);
  ASSERT_EQ(mf_encoding_get_local_latents(raw, zl.data(), zl.size(), &nl), MF_OK);
  ASSERT_EQ(mf_encoding_get_global_latents(raw, zg.data(), zg.size(), &ng), MF_OK);

  // Encoding is deterministic.
  mf_encoding* again = nullptr;
  ASSERT_EQ(mf_encode(model.get(), input.get(), nullptr, &again), MF_OK);
  const EncodingPtr pagain(again);
  std::vector<float> zl2(nl);
  ASSERT_EQ(mf_encoding_get_local_latents(again, zl2.data(), zl2.size(), nullptr), MF_OK);
  EXPECT_EQ(zl, zl2);

  // Decoding: frame_count 0 keeps the span; 60 fps doubles the frames.
  mf_motion* dec = nullptr;
  ASSERT_EQ(mf_decode(raw, 60.0, 0, nullptr, &dec), MF_OK) << describe(MF_OK);
  const MotionPtr pdec(dec);
  EXPECT_EQ(frame_count(dec), 139);
  // Arbitrary times give the same frames as the regular grid.
  const double times[] = {0.5, 0.0, 1.0 / 60.0};
  mf_motion* at_times = nullptr;
  ASSERT_EQ(mf_decode_times(raw, times, 3, 60.0, nullptr, &at_times), MF_OK);
  const MotionPtr pat(at_times);
  ASSERT_EQ(frame_count(at_times), 3);
  const std::vector<float> grid = rotations(dec), picked = rotations(at_times);
  const int J = 7;
  for (int i = 0; i < 4 * J; ++i) {
    EXPECT_NEAR(picked[i], grid[30 * 4 * J + i], 1e-5);          // t = 0.5 s = frame 30
    EXPECT_NEAR(picked[4 * J + i], grid[i], 1e-5);               // t = 0
    EXPECT_NEAR(picked[2 * 4 * J + i], grid[4 * J + i], 1e-5);   // t = 1/60 s
  }
  // The input's root path: exact at input frames.
  mf_codec_options options;
  ASSERT_EQ(mf_codec_options_init(&options), MF_OK);
  EXPECT_EQ(options.struct_size, sizeof options);
  options.root_source = MF_ROOT_FROM_INPUT;
  mf_motion* with_root = nullptr;
  ASSERT_EQ(mf_decode(raw, 30.0, 70, &options, &with_root), MF_OK);
  const MotionPtr pwr(with_root);
  const std::vector<float> a = root_positions(input.get()), b = root_positions(with_root);
  for (size_t i = 0; i < a.size(); ++i) ASSERT_NEAR(a[i], b[i], 1e-5);

  // Latent editing: the same latents decode the same; other latents differ.
  mf_encoding* same = nullptr;
  ASSERT_EQ(mf_encoding_with_latents(raw, zl.data(), zl.size(), zg.data(), zg.size(), &same), MF_OK);
  const EncodingPtr psame(same);
  mf_motion* dec_same = nullptr;
  ASSERT_EQ(mf_decode(same, 60.0, 0, nullptr, &dec_same), MF_OK);
  const MotionPtr pds(dec_same);
  EXPECT_EQ(rotations(dec_same), grid);
  std::vector<float> zero(zl.size(), 0.0f);
  mf_encoding* edited = nullptr;
  ASSERT_EQ(mf_encoding_with_latents(raw, zero.data(), zero.size(), nullptr, 0, &edited), MF_OK);
  const EncodingPtr pedited(edited);
  mf_motion* dec_edit = nullptr;
  ASSERT_EQ(mf_decode(edited, 60.0, 0, nullptr, &dec_edit), MF_OK);
  const MotionPtr pde(dec_edit);
  EXPECT_NE(rotations(dec_edit), grid);

  // The encoding outlives its model handle.
  mf_model* tmp = nullptr;
  ASSERT_EQ(mf_model_load(tiny_model_path().c_str(), &tmp), MF_OK);
  mf_encoding* orphan = nullptr;
  ASSERT_EQ(mf_encode(tmp, input.get(), nullptr, &orphan), MF_OK);
  mf_model_destroy(tmp);
  mf_motion* dec_orphan = nullptr;
  ASSERT_EQ(mf_decode(orphan, 30.0, 0, nullptr, &dec_orphan), MF_OK);
  EXPECT_EQ(frame_count(dec_orphan), 70);
  mf_motion_destroy(dec_orphan);
  mf_encoding_destroy(orphan);
}

TEST(CApi, ResampleWithThePrior) {
  const std::vector<std::string> prior = methods_with(MF_METHOD_NEEDS_MODEL | MF_METHOD_RESAMPLES);
  ASSERT_FALSE(prior.empty()) << "no registered method resamples with the prior";
  const ModelPtr model = load_tiny_model();
  const MotionPtr input = random_capi_motion(40, 30.0, 13);
  mf_task_options options;
  mf_task_options_init(&options);
  options.method = prior.front().c_str();
  mf_motion* out = nullptr;
  ASSERT_EQ(mf_resample(model.get(), input.get(), 60.0, &options, &out), MF_OK) << describe(MF_OK);
  const MotionPtr result(out);
  EXPECT_EQ(frame_count(out), 79);
}

// The destroy functions accept NULL (a crash fails the test's process) and,
// like every destroy, leave the thread's last error as it was.
TEST(CApi, DestroyAcceptsNull) {
  mf_motion* m = nullptr;
  ASSERT_EQ(mf_motion_load_bvh("/nonexistent/destroy-null.bvh", nullptr, &m), MF_ERROR_IO);
  const std::string message = mf_last_error_message();
  ASSERT_NE(message.find("destroy-null.bvh"), std::string::npos) << message;
  mf_model_destroy(nullptr);
  mf_motion_destroy(nullptr);
  mf_encoding_destroy(nullptr);
  mf_cancel_token_destroy(nullptr);
  EXPECT_EQ(mf_last_error_message(), message);
  mf_cancel_token* token = nullptr;
  ASSERT_EQ(mf_cancel_token_create(&token), MF_OK);
  mf_cancel_token_destroy(token);
  mf_motion_destroy(load_sample().release());
  EXPECT_EQ(mf_last_error_message(), message);
}

}  // namespace
}  // namespace mf::capi_test
