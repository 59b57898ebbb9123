// Helpers shared by the unit tests: a small test skeleton and random motions.
#pragma once

#include <cstdint>
#include <string>

#include "prior/model/nemf.h"
#include "prior/motion/motion.h"

namespace mf::test {

/// A 7-joint skeleton (hips, spine, head, two legs with feet), offsets in metres.
Skeleton small_skeleton();

/// A motion with smooth random local rotations and root path, deterministic in `seed`.
Motion random_motion(const Skeleton& skeleton, int frames, double fps, uint32_t seed);

/// A tiny prior (32-frame window, 3x32 decoder, z_l 8, z_g 4) for fast tests.
NemfConfig tiny_nemf_config();
/// The rig of small_skeleton(), measured from one random motion.
RigInfo tiny_rig();

/// A fresh empty directory under the build tree's test scratch area.
std::string scratch_dir(const std::string& name);

}  // namespace mf::test
