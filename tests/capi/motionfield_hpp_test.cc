// motionfield.hpp, the header-only C++ layer: failed calls become
// motionfield::Error with the C status and message, handles free what they own
// exactly once and move, and each wrapper returns what its C call does.
#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "motionfield.hpp"
#include "tests/capi/capi_test_util.h"
#include "tests/test_util.h"

namespace {

namespace api = motionfield;
using mf::capi_test::sample_bvh;
using mf::capi_test::tiny_model_path;

static_assert(!std::is_copy_constructible_v<api::Motion> && !std::is_copy_assignable_v<api::Motion>);
static_assert(std::is_nothrow_move_constructible_v<api::Model> && std::is_nothrow_move_assignable_v<api::Model>);
static_assert(!std::is_copy_constructible_v<api::CancelToken> && !std::is_copy_constructible_v<api::Encoding>);

// Runs `call` and returns the motionfield::Error it throws (fails if none).
template <class Call>
api::Error error_of(Call&& call) {
  try {
    call();
  } catch (const api::Error& e) {
    return e;
  }
  ADD_FAILURE() << "no motionfield::Error thrown";
  return api::Error(MF_OK, "");
}

api::Motion sample() { return api::Motion::load_bvh(sample_bvh()); }

TEST(MotionfieldHpp, FailedCallsThrowErrorWithTheStatusAndTheMessage) {
  const std::string missing = mf::test::scratch_dir("hpp-missing") + "/missing.bvh";
  const api::Error io = error_of([&] { api::Motion::load_bvh(missing); });
  EXPECT_EQ(io.status(), MF_ERROR_IO);
  EXPECT_STREQ(io.status_name(), "MF_ERROR_IO");
  EXPECT_STREQ(io.what(), mf_last_error_message());
  EXPECT_NE(std::string(io.what()).find("missing.bvh"), std::string::npos) << io.what();

  EXPECT_EQ(error_of([] { api::Model::load(sample_bvh()); }).status(), MF_ERROR_MODEL);
  const api::Error unknown = error_of([] { api::find_method("magic"); });
  EXPECT_EQ(unknown.status(), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(unknown.what()).find("magic"), std::string::npos) << unknown.what();
  EXPECT_EQ(error_of([] { api::set_num_threads(0); }).status(), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(error_of([] { api::inbetween(api::Model(), sample(), {30}); }).status(), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(error_of([] { api::length_unit_scale("furlong"); }).status(), MF_ERROR_INVALID_ARGUMENT);
  // An empty handle is the C API's NULL.
  EXPECT_EQ(error_of([] { api::Motion().frame_count(); }).status(), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(error_of([] { api::resample(api::Model(), sample(), 60.0, {"prior"}); }).status(), MF_ERROR_MODEL);
}

// The handle template with a destroy function that counts, so that frees can be seen.
int destroyed = 0;
int last_destroyed = 0;
void count_destroy(int* p) {
  if (!p) return;
  ++destroyed;
  last_destroyed = *p;
}
using Counted = api::detail::Handle<int, count_destroy>;

TEST(MotionfieldHpp, HandlesFreeWhatTheyOwnExactlyOnce) {
  int a = 1, b = 2, c = 3;
  destroyed = 0;
  {
    Counted first(&a);
    Counted moved(std::move(first));
    EXPECT_EQ(first.get(), nullptr);
    EXPECT_FALSE(first);
    EXPECT_EQ(moved.get(), &a);
    Counted other(&b);
    other = std::move(moved);  // frees b, takes a
    EXPECT_EQ(destroyed, 1);
    EXPECT_EQ(last_destroyed, 2);
    EXPECT_EQ(other.get(), &a);
    Counted& self = other;
    other = std::move(self);  // self-move keeps it
    EXPECT_EQ(other.get(), &a);
    EXPECT_EQ(destroyed, 1);
    Counted released(&c);
    EXPECT_EQ(released.release(), &c);
    EXPECT_FALSE(released);
  }
  EXPECT_EQ(destroyed, 2);  // a at the end of the scope; c was released, never freed
  EXPECT_EQ(last_destroyed, 1);
}

TEST(MotionfieldHpp, MovedHandlesKeepWorking) {
  api::Motion walk = sample();
  mf_motion* raw = walk.get();
  api::Motion moved = std::move(walk);
  EXPECT_FALSE(walk);
  EXPECT_EQ(moved.get(), raw);
  EXPECT_EQ(moved.frame_count(), 61);
  api::CancelToken token = api::CancelToken::create();
  api::CancelToken other = std::move(token);
  EXPECT_FALSE(other.is_cancelled());
  other.cancel();
  EXPECT_TRUE(other.is_cancelled());
  other.reset();
  EXPECT_FALSE(other.is_cancelled());
}

TEST(MotionfieldHpp, MotionsReadWriteAndReportWhatTheCApiDoes) {
  const api::Motion walk = sample();
  EXPECT_EQ(walk.frame_count(), 61);
  EXPECT_EQ(walk.joint_count(), 21);  // its joint_Root container is folded into Hips
  EXPECT_EQ(walk.fps(), 30.0);
  EXPECT_EQ(walk.length_scale(), 0.01);
  const std::vector<std::string> names = walk.joint_names();
  ASSERT_EQ(names.size(), 21u);
  EXPECT_EQ(names.front(), "Hips");
  EXPECT_EQ(walk.parents().front(), -1);
  EXPECT_EQ(walk.offsets().size(), 21u * 3);
  EXPECT_EQ(walk.rotations(), mf::capi_test::rotations(walk.get()));
  EXPECT_EQ(walk.root_positions(), mf::capi_test::root_positions(walk.get()));
  EXPECT_EQ(walk.global_positions().size(), 61u * 21 * 3);
  EXPECT_EQ(walk.warnings(), "");

  const std::string text = walk.to_bvh();
  EXPECT_EQ(text.rfind("HIERARCHY", 0), 0u);
  const api::Motion again = api::Motion::load_bvh_from_memory(text);
  EXPECT_EQ(again.joint_names(), names);
  EXPECT_EQ(again.frame_count(), 61);
  const std::string path = mf::test::scratch_dir("hpp-round-trip") + "/walk.bvh";
  walk.save_bvh(path, 1.0);  // written in metres
  const api::Motion metres = api::Motion::load_bvh(path, 1.0);
  EXPECT_NEAR(metres.offsets()[3 * 1 + 1], walk.offsets()[3 * 1 + 1], 1e-5);
  EXPECT_EQ(api::Motion::load_bvh(path).length_scale(), 1.0);  // detected
}

TEST(MotionfieldHpp, TasksMethodsAndWarnings) {
  const api::Motion walk = sample();
  const api::Motion keyed = api::inbetween(api::Model(), walk, {0, 30, 60}, {"interp"});
  const std::vector<float> r_in = walk.rotations(), r_out = keyed.rotations();
  const size_t frame = static_cast<size_t>(walk.joint_count()) * 4;
  EXPECT_TRUE(std::equal(r_in.begin() + 30 * frame, r_in.begin() + 31 * frame, r_out.begin() + 30 * frame));
  EXPECT_FALSE(std::equal(r_in.begin() + 10 * frame, r_in.begin() + 11 * frame, r_out.begin() + 10 * frame));
  EXPECT_EQ(api::fill(api::Model(), walk, 10, 20).frame_count(), 61);

  const api::Motion rounded = api::resample(api::Model(), walk, 23.3);
  EXPECT_EQ(rounded.frame_count(), 47);
  EXPECT_NE(rounded.warnings().find("rounded down to 47 frames"), std::string::npos) << rounded.warnings();
  const api::ResampledFrameCount count = api::resample_frame_count(61, 30.0, 23.3);
  EXPECT_EQ(count.frames, 47);
  EXPECT_TRUE(count.rounded);

  EXPECT_EQ(api::default_method(api::Model()), "interp");
  const api::MethodInfo interp = api::find_method("interp");
  EXPECT_TRUE(interp.completes());
  EXPECT_FALSE(interp.needs_model());
  const std::vector<api::MethodInfo> all = api::methods();
  EXPECT_EQ(all.size(), mf::capi_test::methods_with(0).size());
  EXPECT_EQ(all.front().name, mf::capi_test::methods_with(0).front());
  EXPECT_EQ(api::length_unit_scale("in"), 0.0254);
}

TEST(MotionfieldHpp, ProgressCancelsAndItsExceptionsComeBack) {
  const api::Motion walk = sample();
  api::TaskOptions options;
  options.method = "interp";
  int calls = 0;
  options.progress = [&](const mf_progress& p) {
    EXPECT_GE(p.struct_size, sizeof(uint32_t));
    ++calls;
    return true;
  };
  api::inbetween(api::Model(), walk, {0, 60}, options);
  EXPECT_GE(calls, 1);

  options.progress = [](const mf_progress&) { return false; };
  EXPECT_EQ(error_of([&] { api::inbetween(api::Model(), walk, {0, 60}, options); }).status(), MF_ERROR_CANCELLED);

  options.progress = [](const mf_progress&) -> bool { throw std::domain_error("stop here"); };
  try {
    api::inbetween(api::Model(), walk, {0, 60}, options);
    ADD_FAILURE() << "the callback's exception was not rethrown";
  } catch (const std::domain_error& e) {
    EXPECT_STREQ(e.what(), "stop here");
  }

  api::CancelToken token = api::CancelToken::create();
  token.cancel();
  api::TaskOptions cancelled;
  cancelled.cancel = &token;
  EXPECT_EQ(error_of([&] { api::fill(api::Model(), walk, 10, 20, cancelled); }).status(), MF_ERROR_CANCELLED);
}

TEST(MotionfieldHpp, ModelsAndTheCodec) {
  const api::Model model = api::Model::load(tiny_model_path());
  EXPECT_EQ(model.joint_count(), 7);
  EXPECT_EQ(model.joint_names().size(), 7u);
  EXPECT_EQ(model.window(), 32);
  EXPECT_GT(model.fps(), 0.0);
  EXPECT_EQ(api::default_method(model), "nemf");
  EXPECT_FALSE(model.has_inbetweener("citl"));
  EXPECT_EQ(error_of([&] { model.has_inbetweener("bogus"); }).status(), MF_ERROR_INVALID_ARGUMENT);
  const std::vector<uint8_t>& bytes = mf::capi_test::tiny_model_bytes();
  EXPECT_EQ(api::Model::load_from_memory(bytes.data(), bytes.size()).joint_count(), 7);

  const api::Motion input(mf::capi_test::random_capi_motion(40, 30.0, 7).release());
  const api::Encoding code = api::encode(model, input);
  ASSERT_GE(code.window_count(), 1);
  EXPECT_NEAR(code.duration(), 39 / 30.0, 1e-9);
  EXPECT_EQ(code.window_times().size(), static_cast<size_t>(code.window_count()));
  const api::Motion decoded = code.decode(30.0);
  EXPECT_EQ(decoded.frame_count(), 40);
  const api::Encoding same = code.with_latents(code.local_latents(), {});
  EXPECT_EQ(same.decode(30.0).rotations(), decoded.rotations());
  EXPECT_EQ(code.decode_times({0.0, 0.5}, 30.0).frame_count(), 2);
  std::vector<float> zeros(code.local_latents().size(), 0.0f);
  EXPECT_NE(code.with_latents(zeros, {}).decode(30.0).rotations(), decoded.rotations());
}

}  // namespace
