// Fuzz target: the FBX reader (prior/motion/fbx_reader.h: assimp, then the
// scene conversion of node_animation.h) on any bytes.
// Contract checked: malformed input throws mf::InputError (any other
// exception, a crash or a sanitizer report is a finding, including one inside
// assimp); a motion read is valid and has frames, and the unit is positive.
#include <cstdint>

#include "fuzz/fuzz_check.h"
#include "prior/motion/errors.h"
#include "prior/motion/fbx_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  mf::Motion motion;
  double unit = 0;
  try {
    motion = mf::read_fbx_motion(data, size, {}, &unit);
  } catch (const mf::InputError&) {
    return 0;
  }
  motion.validate();  // must not throw for a motion the reader returned
  MF_FUZZ_CHECK(motion.num_frames() >= 1 && motion.num_joints() >= 1);
  MF_FUZZ_CHECK(unit > 0);
  return 0;
}
