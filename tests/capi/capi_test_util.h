// Helpers of the C API tests: handle ownership, array getters, motions from
// the C++ test motions, and a tiny random model file (written once per process
// with the C++ model code; everything under test goes through motionfield.h).
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "motionfield.h"
#include "prior/motion/motion.h"

namespace mf::capi_test {

struct MotionDeleter {
  void operator()(mf_motion* m) const { mf_motion_destroy(m); }
};
struct ModelDeleter {
  void operator()(mf_model* m) const { mf_model_destroy(m); }
};
struct EncodingDeleter {
  void operator()(mf_encoding* e) const { mf_encoding_destroy(e); }
};
struct TokenDeleter {
  void operator()(mf_cancel_token* t) const { mf_cancel_token_destroy(t); }
};
using MotionPtr = std::unique_ptr<mf_motion, MotionDeleter>;
using ModelPtr = std::unique_ptr<mf_model, ModelDeleter>;
using EncodingPtr = std::unique_ptr<mf_encoding, EncodingDeleter>;
using TokenPtr = std::unique_ptr<mf_cancel_token, TokenDeleter>;

/// The status and the thread's message, for assertion messages.
std::string describe(int status);

/// Path of the bundled sample (61 frames at 30 fps, 22 joints).
std::string sample_bvh();

/// A tiny random model (7-joint test skeleton, window 32, z_l 8, z_g 4),
/// written once per process; its path and its bytes.
const std::string& tiny_model_path();
const std::vector<uint8_t>& tiny_model_bytes();
ModelPtr load_tiny_model();

/// A C API motion holding exactly the C++ motion's values (as floats).
MotionPtr to_capi(const Motion& m);
/// A random motion on the tiny model's skeleton (mf::test::small_skeleton).
MotionPtr random_capi_motion(int frames, double fps, uint32_t seed);

std::vector<float> rotations(const mf_motion* m);
std::vector<float> root_positions(const mf_motion* m);
/// World joint positions [frames * joints * 3], metres (mf_motion_get_global_positions).
std::vector<float> global_positions(const mf_motion* m);
int frame_count(const mf_motion* m);

/// The bytes of a whole file ("" when it cannot be read).
std::string read_text(const std::string& path);

/// Names of registered methods with all of `flags`.
std::vector<std::string> methods_with(uint32_t flags);

}  // namespace mf::capi_test
