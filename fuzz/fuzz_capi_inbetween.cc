// Fuzz target: the C API's tasks with a model: mf_inbetween with any keyframe
// list, mf_fill and mf_resample, with every registered method (and unknown
// names), on a motion made from arrays on the model's skeleton, and with
// mf_task_options of any struct_size (NULL, too small, exact, larger with zero
// or non-zero tails, beyond the 64 KiB limit), any seed, a rig map text,
// a missing rig map file, a cancel token (cancelled or not).
//
// The model: the smallest prior and in-betweeners the loaders accept
// (fuzz/tiny_models.h), written at start-up to a temporary directory and
// loaded with mf_model_load (so the transformers are found next to the prior).
// Solves stay cheap: the progress callback cancels after 0 to 3 calls (the
// latent solvers report every iteration), and the model is not passed when
// the options cannot carry the callback (then only the model-free methods
// run).
//
// About "any struct_size": the options buffer is always struct_size bytes
// (the caller's promise); pointer fields wholly inside struct_size hold valid
// pointers or NULL. A struct_size that ends inside a pointer field is no
// version of the struct any caller could compile: the library must refuse it
// (MF_ERROR_INVALID_ARGUMENT) rather than read half a pointer.
//
// Contract checked: every status is documented and never MF_ERROR_INTERNAL; on
// failure `out` is untouched; a result has the expected frame count and reads
// back.
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "fuzz/capi_checks.h"
#include "fuzz/fuzz_check.h"
#include "fuzz/fuzz_input.h"
#include "fuzz/tiny_models.h"
#include "motionfield.h"
#include "prior/inbetween/inbetweener.h"
#include "prior/model/model_file.h"

namespace {

mf_motion* const kUntouched = reinterpret_cast<mf_motion*>(uintptr_t(0x1));
mf_model* g_model = nullptr;
int32_t g_joints = 0;
std::vector<std::string> g_methods;

struct ProgressBudget {
  int calls_left;
};

int progress(void* user_data, const mf_progress* p) {
  MF_FUZZ_CHECK(p && p->struct_size >= sizeof(uint32_t));
  // user_data is NULL when struct_size ends after `progress` but before `user_data`.
  ProgressBudget* budget = static_cast<ProgressBudget*>(user_data);
  return budget && budget->calls_left-- > 0 ? 0 : 1;
}

// Writes the micro models to a fresh temporary directory, loads them, removes the files.
mf_model* load_micro_model() {
  char dir_template[] = "/tmp/mf-fuzz-model-XXXXXX";
  const char* dir = mkdtemp(dir_template);
  if (!dir) std::abort();
  const std::filesystem::path d(dir);
  const mf::NemfModel prior = mf::fuzz::micro_prior();
  mf::save_nemf(prior, (d / "motionfield-prior.mfm").string());
  for (const mf::InbetweenerKind& kind : mf::inbetweener_kinds())
    mf::save_inbetweener(*mf::fuzz::micro_inbetweener(kind.name, prior.rig()), (d / kind.file_name).string());
  mf_model* model = nullptr;
  if (mf_model_load((d / "motionfield-prior.mfm").c_str(), &model) != MF_OK) {
    std::fprintf(stderr, "cannot load the micro model: %s\n", mf_last_error_message());
    std::abort();
  }
  std::filesystem::remove_all(d);
  return model;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  mf_set_num_threads(1);
  g_model = load_micro_model();
  MF_FUZZ_CHECK(mf_model_get_joint_count(g_model, &g_joints) == MF_OK);
  int32_t count = 0;
  MF_FUZZ_CHECK(mf_method_count(&count) == MF_OK);
  for (int32_t i = 0; i < count; ++i) {
    const char* name = nullptr;
    MF_FUZZ_CHECK(mf_method_get(i, &name, nullptr, nullptr) == MF_OK);
    g_methods.push_back(name);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (!g_model) LLVMFuzzerInitialize(nullptr, nullptr);
  mf::fuzz::FuzzInput in(data, size);

  // The motion, on the model's skeleton (the joint count is sometimes wrong).
  const int32_t frames = static_cast<int32_t>(in.range(1, 40));
  const uint8_t fps_kind = in.range(0, 7);
  const double fps = fps_kind < 4 ? 30.0 : fps_kind == 4 ? 15.0 : fps_kind == 5 ? 60.0 : fps_kind == 6 ? 24.0
                                                                                                        : in.any_double();
  const int32_t joints = in.range(0, 31) == 0 ? static_cast<int32_t>(in.range(-1, g_joints + 1)) : g_joints;
  const size_t J = joints > 0 ? size_t(joints) : 0;
  std::vector<float> rotations(size_t(frames) * J * 4), root(size_t(frames) * 3);
  for (size_t i = 0; i < size_t(frames) * J; ++i) {
    rotations[i * 4] = 1.0f;
    if (!in.flag())
      for (int k = 0; k < 4; ++k) rotations[i * 4 + k] += in.plausible_float();
  }
  for (size_t f = 0; f < size_t(frames); ++f) {
    root[f * 3 + 1] = 0.9f;
    if (!in.flag())
      for (int k = 0; k < 3; ++k) root[f * 3 + k] += in.plausible_float();
  }
  mf_motion* motion = kUntouched;
  if (MF_FUZZ_CALL(mf_motion_create_for_model(g_model, joints, frames, fps, rotations.data(), root.data(), &motion)) !=
      MF_OK) {
    MF_FUZZ_CHECK(motion == kUntouched);
    return 0;
  }

  // The options.
  mf_task_options base;
  MF_FUZZ_CHECK(mf_task_options_init(&base) == MF_OK);
  std::string method_storage, rig_map_storage;
  const uint8_t method_kind = in.range(0, 15);
  if (method_kind < 12 && !g_methods.empty()) {
    base.method = g_methods[in.range(0, static_cast<int64_t>(g_methods.size()) - 1)].c_str();
  } else if (method_kind == 12) {
    base.method = nullptr;
  } else if (method_kind == 13) {
    base.method = "";
  } else {
    method_storage = in.string(24);
    base.method = method_storage.c_str();
  }
  base.seed = in.u32();
  ProgressBudget budget{static_cast<int>(in.range(0, 3))};
  base.progress = progress;
  base.user_data = &budget;
  mf_cancel_token* token = nullptr;
  if (in.range(0, 7) == 0) {
    MF_FUZZ_CHECK(mf_cancel_token_create(&token) == MF_OK);
    if (in.flag()) MF_FUZZ_CHECK(mf_cancel_token_cancel(token) == MF_OK);
    base.cancel = token;
  }
  const uint8_t rig_kind = in.range(0, 15);
  if (rig_kind == 0) {
    rig_map_storage = in.string(64);
    base.rig_map = rig_map_storage.c_str();
  } else if (rig_kind == 1) {
    base.rig_map_path = "/nonexistent/motionfield-fuzz-rig-map.json";
  } else if (rig_kind == 2) {
    base.rig_map_path = "/tmp";  // a directory
  }

  const uint8_t size_kind = in.range(0, 15);
  uint32_t struct_size = sizeof(mf_task_options);
  bool options_null = false;
  if (size_kind == 0) options_null = true;
  else if (size_kind == 1) struct_size = static_cast<uint32_t>(in.range(0, 8 * sizeof(mf_task_options)));
  else if (size_kind == 2) struct_size = in.u32();
  else if (size_kind == 3) struct_size = static_cast<uint32_t>(in.range(0, 8)) * 8;  // every older layout
  else if (size_kind == 4) struct_size = sizeof(mf_task_options) + static_cast<uint32_t>(in.range(1, 64));
  else if (size_kind == 5) struct_size = 65536 + static_cast<uint32_t>(in.range(0, 1));
  // The buffer holds struct_size bytes (at most 64 KiB + 1 here: a larger
  // struct_size is refused before anything is read).
  const size_t buffer_size = std::max<size_t>(std::min<size_t>(struct_size, 65537), sizeof(mf_task_options));
  std::vector<uint64_t> storage(buffer_size / 8 + 1, 0);
  unsigned char* buffer = reinterpret_cast<unsigned char*>(storage.data());
  std::memcpy(buffer, &base, sizeof base);
  std::memcpy(buffer, &struct_size, sizeof struct_size);
  // A struct_size cutting a pointer field must be refused (see the top of the file).
  const size_t pointer_fields[] = {offsetof(mf_task_options, method),    offsetof(mf_task_options, progress),
                                   offsetof(mf_task_options, user_data), offsetof(mf_task_options, cancel),
                                   offsetof(mf_task_options, rig_map),   offsetof(mf_task_options, rig_map_path)};
  bool cuts_pointer = false;
  for (size_t off : pointer_fields) cuts_pointer |= struct_size > off && struct_size < off + sizeof(void*);
  cuts_pointer &= !options_null;
  if (struct_size > sizeof(mf_task_options) && in.range(0, 3) == 0 && struct_size <= 65536)
    buffer[sizeof(mf_task_options) + in.range(0, struct_size - sizeof(mf_task_options) - 1)] = in.u8() | 1;
  const bool progress_read = !options_null && struct_size <= 65536 &&
                             struct_size >= offsetof(mf_task_options, user_data) + sizeof(void*);
  // Without the callback (and the cancel) the solvers would run to the end: no model then.
  const mf_model* model = progress_read && in.range(0, 15) != 0 ? g_model : nullptr;
  const mf_task_options* options = options_null ? nullptr : reinterpret_cast<const mf_task_options*>(buffer);

  mf_motion* out = kUntouched;
  int status;
  int32_t expected_frames = frames;
  switch (in.range(0, 2)) {
    case 0: {
      std::vector<int32_t> keys(in.range(0, 8));
      int32_t next = 0;
      for (int32_t& k : keys) {
        const uint8_t kind = in.range(0, 7);
        if (kind < 5)  // mostly increasing, in range; saturating after a huge key (no overflow in the harness)
          next = static_cast<int32_t>(std::min<int64_t>(INT32_MAX, int64_t{next} + in.range(0, frames / 2 + 1)));
        else if (kind == 5) next = static_cast<int32_t>(in.range(-2, frames + 1));
        else next = static_cast<int32_t>(in.u32());
        k = next;
      }
      status = MF_FUZZ_CALL(mf_inbetween(model, motion, keys.data(), keys.size(), options, &out));
      break;
    }
    case 1: {
      const int32_t a = static_cast<int32_t>(in.range(-1, frames + 1));
      const int32_t b = static_cast<int32_t>(in.range(-1, frames + 1));
      status = MF_FUZZ_CALL(mf_fill(model, motion, a, b, options, &out));
      break;
    }
    default: {
      const uint8_t k = in.range(0, 7);
      const double target = k < 2 ? 30.0 : k == 2 ? 60.0 : k == 3 ? 15.0 : k == 4 ? 24.0 : k == 5 ? 120.0
                                                                                                    : in.any_double();
      double fps_in = 0;
      MF_FUZZ_CHECK(mf_motion_get_fps(motion, &fps_in) == MF_OK);
      int32_t rounded = 0;
      if (mf_resample_frame_count(frames, fps_in, target, &expected_frames, &rounded) != MF_OK) expected_frames = -1;
      // Up to 10 million output frames are allowed (by design); that many take
      // seconds and are not a finding.
      if (expected_frames > 10000) {
        mf_cancel_token_destroy(token);
        mf_motion_destroy(motion);
        return 0;
      }
      status = MF_FUZZ_CALL(mf_resample(model, motion, target, options, &out));
      break;
    }
  }
  if (cuts_pointer) MF_FUZZ_CHECK(status == MF_ERROR_INVALID_ARGUMENT);
  if (status == MF_OK) {
    int32_t n = 0;
    MF_FUZZ_CHECK(mf_motion_get_frame_count(out, &n) == MF_OK && n == expected_frames);
    size_t needed = 0;
    MF_FUZZ_CHECK(mf_motion_get_global_positions(out, nullptr, 0, &needed) == MF_OK);
    std::vector<float> positions(needed);
    MF_FUZZ_CHECK(mf_motion_get_global_positions(out, positions.data(), positions.size(), &needed) == MF_OK);
    mf_motion_destroy(out);
  } else {
    MF_FUZZ_CHECK(out == kUntouched);
  }
  mf_cancel_token_destroy(token);
  mf_motion_destroy(motion);
  return 0;
}
