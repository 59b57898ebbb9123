// N threads solving different inputs on one shared model give the same results
// as solving them one after another (baselines, the prior's methods, encode
// and decode), with one intra-op thread so that results are bitwise
// reproducible.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <thread>

#include "prior/inbetween/inbetweener.h"
#include "prior/model/model_file.h"
#include "tests/capi/capi_test_util.h"
#include "tests/test_util.h"

namespace mf::capi_test {
namespace {

constexpr int kInputs = 6;
constexpr int kThreads = 3;

struct Output {
  std::vector<float> rotations, root_positions;
  int status = -1;
  bool operator==(const Output& o) const {
    return status == o.status && rotations == o.rotations && root_positions == o.root_positions;
  }
};

Output capture(int status, mf_motion* m) {
  Output o;
  o.status = status;
  EXPECT_EQ(status, MF_OK) << describe(status);
  if (status == MF_OK) {
    o.rotations = rotations(m);
    o.root_positions = root_positions(m);
  }
  mf_motion_destroy(m);
  return o;
}

// Runs job(i) for every input, first one after another, then from kThreads
// threads at once (thread t takes inputs t, t + kThreads, ...), and compares.
void expect_same_results_concurrently(const std::function<Output(int)>& job, int inputs = kInputs) {
  std::vector<Output> sequential(inputs), concurrent(inputs);
  for (int i = 0; i < inputs; ++i) sequential[i] = job(i);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      for (int i = t; i < inputs; i += kThreads) concurrent[i] = job(i);
    });
  for (std::thread& t : threads) t.join();
  for (int i = 0; i < inputs; ++i) {
    EXPECT_EQ(sequential[i].status, MF_OK) << "input " << i;
    EXPECT_FALSE(sequential[i].rotations.empty());
    EXPECT_TRUE(sequential[i] == concurrent[i]) << "input " << i << " differs when solved concurrently";
  }
}

class CApiConcurrency : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(mf_set_num_threads(1), MF_OK);
    model_ = load_tiny_model();
    for (int i = 0; i < kInputs; ++i) inputs_.push_back(random_capi_motion(30 + 7 * i, 30.0, 100 + i));
  }
  ModelPtr model_;
  std::vector<MotionPtr> inputs_;
};

TEST_F(CApiConcurrency, Baselines) {
  for (const char* method : {"interp", "zerovel"}) {
    expect_same_results_concurrently([&](int i) {
      mf_task_options options;
      mf_task_options_init(&options);
      options.method = method;
      const int32_t last = frame_count(inputs_[i].get()) - 1;
      const int32_t keys[] = {0, last / 3, last};
      mf_motion* out = nullptr;
      const int status = mf_inbetween(model_.get(), inputs_[i].get(), keys, 3, &options, &out);
      return capture(status, out);
    });
  }
}

TEST_F(CApiConcurrency, ResamplingWithThePrior) {
  const std::vector<std::string> methods = methods_with(MF_METHOD_NEEDS_MODEL | MF_METHOD_RESAMPLES);
  ASSERT_FALSE(methods.empty()) << "no registered method resamples with the prior";
  for (const std::string& method : methods) {
    expect_same_results_concurrently([&](int i) {
      mf_task_options options;
      mf_task_options_init(&options);
      options.method = method.c_str();
      mf_motion* out = nullptr;
      const int status = mf_resample(model_.get(), inputs_[i].get(), 45.0, &options, &out);
      return capture(status, out);
    });
  }
}

TEST_F(CApiConcurrency, InbetweeningWithThePrior) {
  const std::vector<std::string> methods = methods_with(MF_METHOD_NEEDS_MODEL | MF_METHOD_COMPLETES);
  ASSERT_FALSE(methods.empty()) << "no registered method in-betweens with the prior";
  // Short inputs (within one 32-frame window of the tiny model): solving is the slow part.
  constexpr int kSolves = 3;
  std::vector<MotionPtr> inputs;
  for (int i = 0; i < kSolves; ++i) inputs.push_back(random_capi_motion(16 + 3 * i, 30.0, 200 + i));
  expect_same_results_concurrently([&](int i) {
    mf_task_options options;
    mf_task_options_init(&options);
    options.method = methods.front().c_str();
    options.seed = 7;
    const int32_t last = frame_count(inputs[i].get()) - 1;
    const int32_t keys[] = {0, last / 2, last};
    mf_motion* out = nullptr;
    const int status = mf_inbetween(model_.get(), inputs[i].get(), keys, 3, &options, &out);
    return capture(status, out);
  }, kSolves);
}

TEST_F(CApiConcurrency, EncodeAndDecode) {
  expect_same_results_concurrently([&](int i) {
    mf_encoding* code = nullptr;
    int status = mf_encode(model_.get(), inputs_[i].get(), nullptr, &code);
    mf_motion* out = nullptr;
    if (status == MF_OK) status = mf_decode(code, 50.0, 0, nullptr, &out);
    mf_encoding_destroy(code);
    return capture(status, out);
  });
}

// The learned default method of a model with its transformers next to it (the
// shipped layout: today "nemf-detail", the two-stage transformer's fill refined
// by the prior's solver) and the transformer methods themselves, on one shared
// model handle from several threads: the serial results bit for bit. Tiny
// random networks (the shipped ones take seconds per solve; the code paths are
// the same).
TEST_F(CApiConcurrency, LearnedDefaultAndTransformerMethods) {
  const std::string dir = test::scratch_dir("capi-concurrency-" + std::to_string(::getpid()));
  const std::string prior = dir + "/motionfield-prior.mfm";
  std::ofstream(prior, std::ios::binary)
      .write(reinterpret_cast<const char*>(tiny_model_bytes().data()),
             static_cast<std::streamsize>(tiny_model_bytes().size()));
  const RigInfo rig = load_nemf(prior).rig();
  save_inbetweener(*test::tiny_transformer(kTwoStageKind, rig, 1), dir + "/motionfield-twostage.mfm");
  save_inbetweener(*test::tiny_transformer(kCitlKind, rig, 2), dir + "/motionfield-citl.mfm");
  mf_model* raw = nullptr;
  ASSERT_EQ(mf_model_load(prior.c_str(), &raw), MF_OK) << describe(MF_ERROR_MODEL);
  const ModelPtr model(raw);
  const char* default_name = nullptr;
  ASSERT_EQ(mf_default_method(model.get(), &default_name), MF_OK);
  ASSERT_NE(std::string(default_name), "interp") << "the model's default method is not a learned one";

  constexpr int kSolves = 3;
  std::vector<MotionPtr> inputs;
  for (int i = 0; i < kSolves; ++i) inputs.push_back(random_capi_motion(18 + 3 * i, 30.0, 300 + i));
  for (const char* method : {static_cast<const char*>(nullptr), "detail", "citl"}) {
    SCOPED_TRACE(method ? method : default_name);
    expect_same_results_concurrently([&](int i) {
      mf_task_options options;
      mf_task_options_init(&options);
      options.method = method;  // NULL: the model's default
      options.seed = 11;
      const int32_t last = frame_count(inputs[i].get()) - 1;
      const int32_t keys[] = {0, last / 2, last};
      mf_motion* out = nullptr;
      const int status = mf_inbetween(model.get(), inputs[i].get(), keys, 3, &options, &out);
      return capture(status, out);
    }, kSolves);
  }
  std::error_code ignored;
  std::filesystem::remove_all(dir, ignored);
}

}  // namespace
}  // namespace mf::capi_test
