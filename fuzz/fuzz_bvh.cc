// Fuzz target: the BVH reader (prior/motion/bvh.h) and the conversion to and
// from the internal motion (prior/motion/motion_bvh.h), on any bytes.
// Contract checked: malformed text throws mf::BvhError whose message starts
// with the source name (any other exception, a crash or a sanitizer report is
// a finding); a document that parses validates, formats and reads back with
// the same shape; the conversion to a motion and back throws only
// mf::InputError; a skeleton with every humanoid part gets an anatomy of unit
// rotations, from its motion and, when its rest pose is a T or A pose, from
// that pose.
#include <cmath>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_check.h"
#include "prior/motion/bvh.h"
#include "prior/motion/motion_bvh.h"
#include "prior/rig/retarget.h"
#include "prior/rig/rig_map.h"
#include "prior/rig/units.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  mf::BvhDocument doc;
  try {
    doc = mf::parse_bvh(text, "in.bvh");
  } catch (const mf::BvhError& e) {
    MF_FUZZ_CHECK(std::string(e.what()).rfind("in.bvh:", 0) == 0);
    return 0;
  }
  MF_FUZZ_CHECK(doc.num_frames >= 1 && doc.frame_time > 0);
  doc.validate();  // must not throw for a parsed document
  const std::string formatted = mf::format_bvh(doc);
  const mf::BvhDocument again = mf::parse_bvh(formatted, "formatted.bvh");
  MF_FUZZ_CHECK(again.joints.size() == doc.joints.size());
  MF_FUZZ_CHECK(again.num_frames == doc.num_frames);
  MF_FUZZ_CHECK(again.values.size() == doc.values.size());
  try {
    mf::BvhUnits units;
    const mf::Motion motion = mf::motion_from_bvh(doc, units);
    const mf::BvhDocument back = mf::motion_to_bvh(motion, doc, units);
    MF_FUZZ_CHECK(back.num_frames == doc.num_frames);
    (void)mf::detect_length_unit(motion.skeleton);
    const mf::RigParts parts = mf::find_rig_parts(motion.skeleton);
    if (parts.missing().empty()) {
      const bool rest = mf::rest_pose_is_t_or_a(motion.skeleton, parts);
      mf::RigAnatomy anatomy = mf::estimate_anatomy(motion, parts, {0});
      MF_FUZZ_CHECK(mf::take_rest_pose_frames(motion.skeleton, parts, &anatomy) == rest);
      for (const auto* frames : {&anatomy.frames, &anatomy.toe_frames})
        for (const Eigen::Quaterniond& q : *frames)
          MF_FUZZ_CHECK(q.coeffs().allFinite() && std::abs(q.norm() - 1.0) < 1e-6);
    }
  } catch (const mf::InputError&) {
  }
  return 0;
}
