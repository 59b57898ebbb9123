// The transformer in-betweeners through the C API: found next to the prior's
// file by mf_model_load, added by mf_model_with_inbetweener, queried by
// mf_model_has_inbetweener, and the methods that need them (tiny random
// transformers written with the C++ model code; no trained file).
#include <unistd.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "prior/inbetween/inbetweener.h"
#include "prior/model/model_file.h"
#include "prior/model/nemf.h"
#include "tests/capi/capi_test_util.h"
#include "tests/test_util.h"

namespace mf::capi_test {
namespace {

namespace fs = std::filesystem;

// A directory with the tiny prior as motionfield-prior.mfm, and optionally
// tiny transformers next to it.
struct ModelDir {
  std::string dir, prior;
  explicit ModelDir(const std::string& name) {
    dir = test::scratch_dir("capi-inbetweener-" + name + "-" + std::to_string(::getpid()));
    prior = dir + "/motionfield-prior.mfm";
    std::ofstream(prior, std::ios::binary)
        .write(reinterpret_cast<const char*>(tiny_model_bytes().data()),
               static_cast<std::streamsize>(tiny_model_bytes().size()));
  }
  ~ModelDir() {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
  }
  // A tiny random transformer of `kind` on the prior's rig, written as `file`.
  std::string write(const std::string& kind, const std::string& file) const {
    const std::string path = dir + "/" + file;
    save_inbetweener(*test::tiny_transformer(kind, load_nemf(prior).rig(), 1), path);
    return path;
  }
};

ModelPtr load(const std::string& path) {
  mf_model* m = nullptr;
  EXPECT_EQ(mf_model_load(path.c_str(), &m), MF_OK) << describe(MF_ERROR_MODEL);
  return ModelPtr(m);
}

bool has(const mf_model* m, const char* kind) {
  int32_t v = -1;
  EXPECT_EQ(mf_model_has_inbetweener(m, kind, &v), MF_OK);
  return v == 1;
}

int inbetween(const mf_model* model, const mf_motion* input, const std::vector<int32_t>& keys, const char* method,
              MotionPtr* out) {
  mf_task_options options;
  mf_task_options_init(&options);
  options.method = method;
  mf_motion* raw = nullptr;
  const int status = mf_inbetween(model, input, keys.data(), keys.size(), &options, &raw);
  out->reset(raw);
  return status;
}

TEST(CApiInbetweener, LoadedFromNextToThePriorAndUsedByTheMethods) {
  mf_set_num_threads(1);
  ModelDir d("next-to");
  d.write(kTwoStageKind, "motionfield-twostage.mfm");
  d.write(kCitlKind, "motionfield-citl.mfm");
  const ModelPtr model = load(d.prior);
  ASSERT_TRUE(model);
  EXPECT_TRUE(has(model.get(), "twostage"));
  EXPECT_TRUE(has(model.get(), "citl"));

  const MotionPtr input = random_capi_motion(30, 30.0, 4);
  const std::vector<int32_t> keys = {0, 9, 29};
  const std::vector<float> rin = rotations(input.get()), pin = root_positions(input.get());
  const int J = static_cast<int>(rin.size() / 4 / 30);
  for (const char* method : {"context", "detail", "citl", "nemf-citl"}) {
    MotionPtr out;
    ASSERT_EQ(inbetween(model.get(), input.get(), keys, method, &out), MF_OK) << method << ": " << describe(1);
    ASSERT_EQ(frame_count(out.get()), 30);
    const std::vector<float> r = rotations(out.get()), p = root_positions(out.get());
    for (int f : keys) {
      for (int i = 0; i < J * 4; ++i) EXPECT_EQ(r[f * J * 4 + i], rin[f * J * 4 + i]) << method << " frame " << f;
      for (int i = 0; i < 3; ++i) EXPECT_EQ(p[f * 3 + i], pin[f * 3 + i]) << method << " frame " << f;
    }
    for (float v : r) ASSERT_TRUE(std::isfinite(v)) << method;
  }
}

TEST(CApiInbetweener, MissingOrBrokenTransformerFailsWithTheFileName) {
  mf_set_num_threads(1);
  ModelDir d("missing");
  {
    std::ofstream(d.dir + "/motionfield-citl.mfm") << "not a model";
  }
  const ModelPtr model = load(d.prior);  // the prior still loads
  ASSERT_TRUE(model);
  EXPECT_FALSE(has(model.get(), "twostage"));
  EXPECT_FALSE(has(model.get(), "citl"));
  const MotionPtr input = random_capi_motion(20, 30.0, 5);
  MotionPtr out;
  EXPECT_EQ(inbetween(model.get(), input.get(), {0, 19}, "detail", &out), MF_ERROR_MODEL);
  EXPECT_NE(std::string(mf_last_error_message()).find("method 'detail' needs models/motionfield-twostage.mfm"),
            std::string::npos)
      << mf_last_error_message();
  EXPECT_EQ(inbetween(model.get(), input.get(), {0, 19}, "nemf-citl", &out), MF_ERROR_MODEL);
  const std::string message = mf_last_error_message();
  EXPECT_NE(message.find("motionfield-citl.mfm"), std::string::npos) << message;
  EXPECT_NE(message.find("did not load"), std::string::npos) << message;
  EXPECT_FALSE(out);
  // Other methods are unaffected.
  EXPECT_EQ(inbetween(model.get(), input.get(), {0, 19}, "interp", &out), MF_OK);
}

TEST(CApiInbetweener, WithInbetweenerFromAnExplicitPath) {
  mf_set_num_threads(1);
  ModelDir d("explicit");
  const std::string citl = d.write(kCitlKind, "my-citl.mfm");  // not the name looked for
  const ModelPtr model = load(d.prior);
  ASSERT_TRUE(model);
  EXPECT_FALSE(has(model.get(), "citl"));
  mf_model* raw = nullptr;
  ASSERT_EQ(mf_model_with_inbetweener(model.get(), citl.c_str(), &raw), MF_OK) << describe(1);
  const ModelPtr with(raw);
  EXPECT_TRUE(has(with.get(), "citl"));
  EXPECT_FALSE(has(with.get(), "twostage"));
  EXPECT_FALSE(has(model.get(), "citl"));  // the original is unchanged
  const MotionPtr input = random_capi_motion(20, 30.0, 6);
  MotionPtr out;
  EXPECT_EQ(inbetween(with.get(), input.get(), {0, 7, 19}, "citl", &out), MF_OK) << describe(1);

  // Bad input, out-param untouched.
  mf_model* const sentinel = reinterpret_cast<mf_model*>(0x5eed);
  raw = sentinel;
  EXPECT_EQ(mf_model_with_inbetweener(model.get(), (d.dir + "/absent.mfm").c_str(), &raw), MF_ERROR_IO);
  EXPECT_EQ(mf_model_with_inbetweener(model.get(), d.prior.c_str(), &raw), MF_ERROR_MODEL);  // a prior, not a transformer
  EXPECT_EQ(mf_model_with_inbetweener(model.get(), "", &raw), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(mf_model_with_inbetweener(nullptr, citl.c_str(), &raw), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(mf_model_with_inbetweener(model.get(), nullptr, &raw), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(mf_model_with_inbetweener(model.get(), citl.c_str(), nullptr), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(raw, sentinel);
  int32_t v = 7;
  EXPECT_EQ(mf_model_has_inbetweener(model.get(), "lstm", &v), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(mf_model_has_inbetweener(nullptr, "citl", &v), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(mf_model_has_inbetweener(model.get(), "citl", nullptr), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(v, 7);
}

// A transformer file next to the prior that does not load (issue 18, item 6)
// is named with its reason by mf_model_describe, so a client can warn that the
// default method runs without it.
TEST(CApiInbetweener, DescribeNamesTheFileThatDidNotLoad) {
  ModelDir d("describe");
  d.write(kCitlKind, "motionfield-citl.mfm");
  {
    std::ofstream(d.dir + "/motionfield-twostage.mfm") << "MFIB truncated";
  }
  const ModelPtr model = load(d.prior);
  ASSERT_TRUE(model);
  size_t needed = 0;
  ASSERT_EQ(mf_model_describe(model.get(), nullptr, 0, &needed), MF_OK);
  std::string text(needed, '\0');
  ASSERT_EQ(mf_model_describe(model.get(), text.data(), text.size(), &needed), MF_OK);
  text.resize(needed - 1);
  EXPECT_NE(text.find("\"format_version\":1"), std::string::npos) << text;
  EXPECT_NE(text.find("\"twostage\":{\"file\":\"motionfield-twostage.mfm\",\"loaded\":false,\"error\":\""),
            std::string::npos)
      << text;
  EXPECT_EQ(text.find("\"error\":\"\"},\"citl\""), std::string::npos) << "the twostage error is empty: " << text;
  EXPECT_NE(text.find("\"citl\":{\"file\":\"motionfield-citl.mfm\",\"loaded\":true,\"error\":\"\"}"),
            std::string::npos)
      << text;
  const char* default_method = nullptr;
  ASSERT_EQ(mf_default_method(model.get(), &default_method), MF_OK);
  EXPECT_STREQ(default_method, "nemf");  // what the CLI's warning explains
}

}  // namespace
}  // namespace mf::capi_test
