// Fuzz target: the C API entry points that take arrays, without a model:
// mf_motion_create (any joint count, names, parents, offsets, frame count,
// fps, rotations and root positions, including NaN, infinities and
// denormals), the getters with size queries and exact buffers, the BVH
// round trip through memory, mf_motion_create_like, and the model-free tasks
// (mf_inbetween with any keyframe list, mf_fill, mf_resample,
// mf_resample_frame_count) with the baseline methods.
// Contract checked: every status is documented and never MF_ERROR_INTERNAL;
// on failure `out` is untouched; a motion the library accepted saves to BVH
// and reads back with the same joint and frame counts.
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz/capi_checks.h"
#include "fuzz/fuzz_check.h"
#include "fuzz/fuzz_input.h"
#include "motionfield.h"

namespace {

mf_motion* const kUntouched = reinterpret_cast<mf_motion*>(uintptr_t(0x1));

const char* pick_method(mf::fuzz::FuzzInput& in, std::string* storage) {
  switch (in.range(0, 5)) {
    case 0: return nullptr;
    case 1: return "";
    case 2: return "interp";
    case 3: return "zerovel";
    case 4: return "nemf";  // needs a model: MF_ERROR_MODEL without one
    default: *storage = in.string(16); return storage->c_str();
  }
}

// The getters of a valid motion, each with a size query then an exact buffer.
void read_back(const mf_motion* m, int32_t joints, int32_t frames) {
  size_t needed = 0;
  MF_FUZZ_CHECK(MF_FUZZ_CALL(mf_motion_get_rotations(m, nullptr, 0, &needed)) == MF_OK);
  MF_FUZZ_CHECK(needed == size_t(frames) * size_t(joints) * 4);
  std::vector<float> buffer(needed);
  MF_FUZZ_CHECK(MF_FUZZ_CALL(mf_motion_get_rotations(m, buffer.data(), buffer.size(), &needed)) == MF_OK);
  MF_FUZZ_CHECK(MF_FUZZ_CALL(mf_motion_get_global_positions(m, nullptr, 0, &needed)) == MF_OK);
  buffer.assign(needed, 0.0f);
  MF_FUZZ_CHECK(MF_FUZZ_CALL(mf_motion_get_global_positions(m, buffer.data(), buffer.size(), &needed)) == MF_OK);
  if (needed > 0) {  // one too small: BUFFER_TOO_SMALL, buffer untouched
    buffer.assign(needed, 7.0f);
    MF_FUZZ_CHECK(MF_FUZZ_CALL(mf_motion_get_global_positions(m, buffer.data(), needed - 1, &needed)) ==
                  MF_ERROR_BUFFER_TOO_SMALL);
    for (float v : buffer) MF_FUZZ_CHECK(v == 7.0f);
  }
  MF_FUZZ_CHECK(MF_FUZZ_CALL(mf_motion_get_root_positions(m, nullptr, 0, &needed)) == MF_OK);
  buffer.assign(needed, 0.0f);
  MF_FUZZ_CHECK(MF_FUZZ_CALL(mf_motion_get_root_positions(m, buffer.data(), buffer.size(), &needed)) == MF_OK);
  for (int32_t j = 0; j < joints; ++j) {
    MF_FUZZ_CHECK(MF_FUZZ_CALL(mf_motion_get_joint_name(m, j, nullptr, 0, &needed)) == MF_OK);
    std::string name(needed, '\0');
    MF_FUZZ_CHECK(MF_FUZZ_CALL(mf_motion_get_joint_name(m, j, name.data(), name.size(), &needed)) == MF_OK);
  }
  char warnings[256];
  MF_FUZZ_CALL(mf_motion_get_warnings(m, warnings, sizeof warnings, &needed));
}

// Saves to BVH in memory and reads it back.
void bvh_round_trip(const mf_motion* m, int32_t joints, int32_t frames, mf::fuzz::FuzzInput& in) {
  mf_bvh_options options;
  MF_FUZZ_CHECK(mf_bvh_options_init(&options) == MF_OK);
  const uint8_t scale = in.range(0, 3);
  options.length_scale = scale == 0 ? 0.0 : scale == 1 ? 0.01 : scale == 2 ? 1.0 : in.any_double();
  size_t needed = 0;
  if (MF_FUZZ_CALL(mf_motion_save_bvh_to_memory(m, &options, nullptr, 0, &needed)) != MF_OK) return;
  std::string text(needed, '\0');
  MF_FUZZ_CHECK(MF_FUZZ_CALL(mf_motion_save_bvh_to_memory(m, &options, text.data(), text.size(), &needed)) ==
                MF_OK);
  mf_motion* back = kUntouched;
  const int status = MF_FUZZ_CALL(mf_motion_load_bvh_from_memory(text.data(), needed - 1, &options, &back));
  if (status != MF_OK) {
    std::fprintf(stderr, "a saved motion does not read back: %s\n%s\n", mf_last_error_message(), text.c_str());
    std::abort();
  }
  int32_t count = 0;
  MF_FUZZ_CHECK(mf_motion_get_frame_count(back, &count) == MF_OK && count == frames);
  MF_FUZZ_CHECK(mf_motion_get_joint_count(back, &count) == MF_OK && count <= joints + 1);
  mf_motion_destroy(back);
}

void run_tasks(const mf_motion* m, int32_t frames, mf::fuzz::FuzzInput& in) {
  mf_task_options options;
  MF_FUZZ_CHECK(mf_task_options_init(&options) == MF_OK);
  std::string method;
  options.method = pick_method(in, &method);
  const mf_task_options* o = in.flag() ? &options : nullptr;
  mf_motion* out = kUntouched;
  int status;
  switch (in.range(0, 2)) {
    case 0: {
      std::vector<int32_t> keys(in.range(0, 6));
      for (int32_t& k : keys) k = in.flag() ? static_cast<int32_t>(in.range(0, frames)) : static_cast<int32_t>(in.u32());
      status = MF_FUZZ_CALL(mf_inbetween(nullptr, m, keys.empty() && in.flag() ? nullptr : keys.data(), keys.size(), o, &out));
      break;
    }
    case 1: {
      const int32_t a = static_cast<int32_t>(in.range(-1, frames + 1));
      const int32_t b = static_cast<int32_t>(in.range(-1, frames + 1));
      status = MF_FUZZ_CALL(mf_fill(nullptr, m, a, b, o, &out));
      break;
    }
    default: {
      const double fps = in.flag() ? static_cast<double>(in.range(1, 120)) : in.any_double();
      double fps_in = 0;
      MF_FUZZ_CHECK(mf_motion_get_fps(m, &fps_in) == MF_OK);
      int32_t count = -7, rounded = -7;
      if (MF_FUZZ_CALL(mf_resample_frame_count(frames, fps_in, fps, &count, &rounded)) != MF_OK)
        MF_FUZZ_CHECK(count == -7 && rounded == -7);
      // The library allows up to 10 million output frames (by design); a
      // resample to millions of frames takes seconds and is not a finding.
      if (count > 10000) return;
      status = MF_FUZZ_CALL(mf_resample(nullptr, m, fps, o, &out));
      break;
    }
  }
  if (status != MF_OK) {
    MF_FUZZ_CHECK(out == kUntouched);
    return;
  }
  int32_t joints = 0, out_frames = 0;
  MF_FUZZ_CHECK(mf_motion_get_joint_count(out, &joints) == MF_OK);
  MF_FUZZ_CHECK(mf_motion_get_frame_count(out, &out_frames) == MF_OK);
  read_back(out, joints, out_frames);
  mf_motion_destroy(out);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  mf_set_num_threads(1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  mf::fuzz::FuzzInput in(data, size);
  const int32_t joints = static_cast<int32_t>(in.range(-1, 6));
  const int32_t frames = static_cast<int32_t>(in.range(-1, 12));
  const size_t J = joints > 0 ? size_t(joints) : 0, F = frames > 0 ? size_t(frames) : 0;
  std::vector<std::string> names(J);
  std::vector<const char*> name_ptrs(J);
  std::vector<int32_t> parents(J);
  std::vector<float> offsets(J * 3), rotations(F * J * 4), root(F * 3);
  for (size_t j = 0; j < J; ++j) {
    names[j] = in.flag() ? std::string(1, static_cast<char>('A' + j)) : in.string(12);
    name_ptrs[j] = names[j].c_str();
    parents[j] = static_cast<int32_t>(in.flag() ? int64_t(j) - 1 : in.range(-2, joints));
  }
  for (float& v : offsets) v = in.plausible_float();
  for (size_t i = 0; i < F * J; ++i) {
    if (in.flag()) {
      rotations[i * 4] = 1.0f;  // identity, most of the time
    } else {
      for (int k = 0; k < 4; ++k) rotations[i * 4 + k] = in.plausible_float();
    }
  }
  for (float& v : root) v = in.plausible_float();
  const uint8_t fps_kind = in.range(0, 3);
  const double fps = fps_kind == 0 ? 30.0 : fps_kind == 1 ? 24.0 : fps_kind == 2 ? 60.0 : in.any_double();
  const bool null_names = in.range(0, 15) == 0;

  mf_motion* m = kUntouched;
  const int status = MF_FUZZ_CALL(mf_motion_create(joints, null_names ? nullptr : name_ptrs.data(), parents.data(),
                                                   offsets.data(), frames, fps, rotations.data(), root.data(), &m));
  if (status != MF_OK) {
    MF_FUZZ_CHECK(m == kUntouched);
    return 0;
  }
  read_back(m, joints, frames);
  bvh_round_trip(m, joints, frames, in);

  mf_motion* like = kUntouched;
  const int32_t like_frames = static_cast<int32_t>(in.range(0, 4));
  std::vector<float> like_rot(size_t(like_frames) * J * 4, 0.0f), like_root(size_t(like_frames) * 3, 0.0f);
  for (size_t i = 0; i < size_t(like_frames) * J; ++i) like_rot[i * 4] = in.plausible_float();
  if (MF_FUZZ_CALL(mf_motion_create_like(m, joints, like_frames, fps, like_rot.data(), like_root.data(), &like)) ==
      MF_OK) {
    mf_motion_destroy(like);
  } else {
    MF_FUZZ_CHECK(like == kUntouched);
  }

  run_tasks(m, frames, in);
  mf_motion_destroy(m);
  return 0;
}
