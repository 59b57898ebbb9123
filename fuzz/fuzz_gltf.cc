// Fuzz target: the glTF reader (prior/motion/gltf_reader.h: tinygltf, then the
// scene conversion of node_animation.h) on any bytes, GLB or JSON, with the
// sampling rate and the animation index taken from the input's first bytes.
// Contract checked: malformed input throws mf::InputError (any other
// exception, a crash or a sanitizer report is a finding); a motion read is
// valid, has frames, and, when glTF can hold it, writes and reads back with
// the same joints and frames.
#include <cstdint>
#include <string>

#include "fuzz/fuzz_check.h"
#include "prior/motion/errors.h"
#include "prior/motion/gltf_reader.h"
#include "prior/motion/motion_gltf.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  mf::SceneReadOptions options;
  // A first byte '#' is a recipe: a rate and an index, then the file.
  if (size >= 3 && data[0] == '#') {
    options.fps = data[1] % 4 == 0 ? 0.0 : data[1] * 0.5;
    options.animation_index = data[2] % 3;
    data += 3;
    size -= 3;
  }
  mf::Motion motion;
  try {
    motion = mf::read_gltf_motion(data, size, "", options);
  } catch (const mf::InputError&) {
    return 0;
  }
  motion.validate();  // must not throw for a motion the reader returned
  MF_FUZZ_CHECK(motion.num_frames() >= 1 && motion.num_joints() >= 1);
  std::vector<uint8_t> again;
  try {
    again = mf::format_gltf(motion, mf::GltfFormat::Binary);
  } catch (const mf::InputError&) {
    return 0;  // a number beyond 32-bit floats
  }
  const mf::Motion back = mf::read_gltf_motion(again.data(), again.size(), "");
  MF_FUZZ_CHECK(back.num_joints() == motion.num_joints());
  MF_FUZZ_CHECK(back.num_frames() == motion.num_frames());
  return 0;
}
