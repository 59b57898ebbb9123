// Freezes the ABI: the size and field offsets of every public struct and the
// value of every public constant. A change here breaks every compiled caller:
// it needs a new MF_ABI_VERSION (and SONAME), not an edit of these numbers.
// (Offsets are those of LP64 platforms: Linux and macOS on 64-bit CPUs.)
#include <gtest/gtest.h>

#include <cstddef>
#include <cstring>

#include "motionfield.h"

namespace {

static_assert(sizeof(void*) == 8, "these layouts are frozen for LP64 platforms");

TEST(CApiLayout, Progress) {
  EXPECT_EQ(sizeof(mf_progress), 32u);  // window, window_count appended
  EXPECT_EQ(offsetof(mf_progress, struct_size), 0u);
  EXPECT_EQ(offsetof(mf_progress, iteration), 4u);
  EXPECT_EQ(offsetof(mf_progress, max_iterations), 8u);
  EXPECT_EQ(offsetof(mf_progress, energy), 16u);
  EXPECT_EQ(offsetof(mf_progress, window), 24u);
  EXPECT_EQ(offsetof(mf_progress, window_count), 28u);
}

TEST(CApiLayout, BvhOptions) {
  EXPECT_EQ(sizeof(mf_bvh_options), 16u);
  EXPECT_EQ(offsetof(mf_bvh_options, struct_size), 0u);
  EXPECT_EQ(offsetof(mf_bvh_options, length_scale), 8u);
}

TEST(CApiLayout, TaskOptions) {
  EXPECT_EQ(sizeof(mf_task_options), 72u);  // max_iterations, then no_fallback in the tail padding, appended
  EXPECT_EQ(offsetof(mf_task_options, struct_size), 0u);
  EXPECT_EQ(offsetof(mf_task_options, method), 8u);
  EXPECT_EQ(offsetof(mf_task_options, seed), 16u);
  EXPECT_EQ(offsetof(mf_task_options, progress), 24u);
  EXPECT_EQ(offsetof(mf_task_options, user_data), 32u);
  EXPECT_EQ(offsetof(mf_task_options, cancel), 40u);
  EXPECT_EQ(offsetof(mf_task_options, rig_map), 48u);
  EXPECT_EQ(offsetof(mf_task_options, rig_map_path), 56u);
  EXPECT_EQ(offsetof(mf_task_options, max_iterations), 64u);
  EXPECT_EQ(offsetof(mf_task_options, no_fallback), 68u);
}

TEST(CApiLayout, TransitionOptions) {
  EXPECT_EQ(sizeof(mf_transition_options), 24u);
  EXPECT_EQ(offsetof(mf_transition_options, struct_size), 0u);
  EXPECT_EQ(offsetof(mf_transition_options, frames), 4u);
  EXPECT_EQ(offsetof(mf_transition_options, from_frame), 8u);
  EXPECT_EQ(offsetof(mf_transition_options, to_frame), 12u);
  EXPECT_EQ(offsetof(mf_transition_options, place), 16u);
  EXPECT_EQ(offsetof(mf_transition_options, only_transition), 20u);
}

TEST(CApiLayout, CodecOptions) {
  EXPECT_EQ(sizeof(mf_constraint_report), 136u);
  EXPECT_EQ(offsetof(mf_constraint_report, struct_size), 0u);
  EXPECT_EQ(offsetof(mf_constraint_report, key_rotations), 4u);
  EXPECT_EQ(offsetof(mf_constraint_report, key_rotation_max_deg), 8u);
  EXPECT_EQ(offsetof(mf_constraint_report, key_roots), 24u);
  EXPECT_EQ(offsetof(mf_constraint_report, key_root_max), 32u);
  EXPECT_EQ(offsetof(mf_constraint_report, targets), 48u);
  EXPECT_EQ(offsetof(mf_constraint_report, target_max), 56u);
  EXPECT_EQ(offsetof(mf_constraint_report, contact_frames), 72u);
  EXPECT_EQ(offsetof(mf_constraint_report, contact_slide_max), 80u);
  EXPECT_EQ(offsetof(mf_constraint_report, trajectory_rows), 96u);
  EXPECT_EQ(offsetof(mf_constraint_report, trajectory_max), 104u);
  EXPECT_EQ(offsetof(mf_constraint_report, facing_mean_deg), 128u);
  EXPECT_EQ(sizeof(mf_codec_options), 12u);
  EXPECT_EQ(offsetof(mf_codec_options, struct_size), 0u);
  EXPECT_EQ(offsetof(mf_codec_options, hop), 4u);
  EXPECT_EQ(offsetof(mf_codec_options, root_source), 8u);
}

TEST(CApiLayout, Constants) {
  EXPECT_EQ(MF_OK, 0);
  EXPECT_EQ(MF_ERROR_INVALID_ARGUMENT, 1);
  EXPECT_EQ(MF_ERROR_BUFFER_TOO_SMALL, 2);
  EXPECT_EQ(MF_ERROR_IO, 3);
  EXPECT_EQ(MF_ERROR_MODEL, 4);
  EXPECT_EQ(MF_ERROR_CANCELLED, 5);
  EXPECT_EQ(MF_ERROR_INTERNAL, 6);
  EXPECT_EQ(MF_ERROR_UNSUPPORTED, 7);
  EXPECT_EQ(MF_ERROR_OUT_OF_MEMORY, 8);
  EXPECT_EQ(MF_METHOD_NEEDS_MODEL, 1u);
  EXPECT_EQ(MF_METHOD_COMPLETES, 2u);
  EXPECT_EQ(MF_METHOD_RESAMPLES, 4u);
  EXPECT_EQ(MF_ROOT_FROM_PRIOR, 0);
  EXPECT_EQ(MF_ROOT_FROM_INPUT, 1);
  EXPECT_EQ(MF_ABI_VERSION, 0);
}

TEST(CApiLayout, GltfOptions) {
  EXPECT_EQ(sizeof(mf_gltf_options), 8u);
  EXPECT_EQ(offsetof(mf_gltf_options, struct_size), 0u);
  EXPECT_EQ(offsetof(mf_gltf_options, format), 4u);
  EXPECT_EQ(MF_GLTF_AUTO, 0);
  EXPECT_EQ(MF_GLTF_BINARY, 1);
  EXPECT_EQ(MF_GLTF_EMBEDDED, 2);
  mf_gltf_options o;
  std::memset(&o, 0xff, sizeof o);
  ASSERT_EQ(mf_gltf_options_init(&o), MF_OK);
  EXPECT_EQ(o.struct_size, sizeof o);
  EXPECT_EQ(o.format, MF_GLTF_AUTO);
}

TEST(CApiLayout, MotionLoadOptions) {
  EXPECT_EQ(sizeof(mf_motion_load_options), 40u);
  EXPECT_EQ(offsetof(mf_motion_load_options, struct_size), 0u);
  EXPECT_EQ(offsetof(mf_motion_load_options, format), 4u);
  EXPECT_EQ(offsetof(mf_motion_load_options, length_scale), 8u);
  EXPECT_EQ(offsetof(mf_motion_load_options, animation), 16u);
  EXPECT_EQ(offsetof(mf_motion_load_options, animation_index), 24u);
  EXPECT_EQ(offsetof(mf_motion_load_options, fps), 32u);
  EXPECT_EQ(MF_FORMAT_AUTO, 0);
  EXPECT_EQ(MF_FORMAT_BVH, 1);
  EXPECT_EQ(MF_FORMAT_GLTF, 2);
  EXPECT_EQ(MF_FORMAT_FBX, 3);
  mf_motion_load_options o;
  std::memset(&o, 0xff, sizeof o);
  ASSERT_EQ(mf_motion_load_options_init(&o), MF_OK);
  EXPECT_EQ(o.struct_size, sizeof o);
  EXPECT_EQ(o.format, MF_FORMAT_AUTO);
  EXPECT_EQ(o.animation, nullptr);
  EXPECT_EQ(o.animation_index, 0);
  EXPECT_EQ(o.fps, 0.0);
}

// The options' defaults are all zero (the rule that makes newer structs safe).
TEST(CApiLayout, InitGivesZeroDefaults) {
  mf_task_options t;
  mf_bvh_options b;
  mf_codec_options c;
  ASSERT_EQ(mf_task_options_init(&t), MF_OK);
  ASSERT_EQ(mf_bvh_options_init(&b), MF_OK);
  ASSERT_EQ(mf_codec_options_init(&c), MF_OK);
  EXPECT_EQ(t.struct_size, sizeof t);
  EXPECT_EQ(t.method, nullptr);
  EXPECT_EQ(t.seed, 0u);
  EXPECT_EQ(t.progress, nullptr);
  EXPECT_EQ(t.user_data, nullptr);
  EXPECT_EQ(t.cancel, nullptr);
  EXPECT_EQ(t.rig_map, nullptr);
  EXPECT_EQ(t.rig_map_path, nullptr);
  EXPECT_EQ(t.max_iterations, 0);
  EXPECT_EQ(t.no_fallback, 0);
  EXPECT_EQ(b.struct_size, sizeof b);
  EXPECT_EQ(b.length_scale, 0.0);
  EXPECT_EQ(c.struct_size, sizeof c);
  EXPECT_EQ(c.hop, 0);
  EXPECT_EQ(c.root_source, 0);
}

}  // namespace
