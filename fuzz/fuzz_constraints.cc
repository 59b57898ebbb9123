// Fuzz target: the constraints file format (tasks/constraints/constraint_spec.h) on any
// bytes (the "trajectory" member included), resolved against a small skeleton
// and validated for a 40-frame motion.
// Contract checked: bad input throws mf::InputError naming the source; what
// parses writes back (to_json) to a document that parses to the same text.
#include <cstdint>
#include <string>

#include "fuzz/fuzz_check.h"
#include "prior/motion/errors.h"
#include "tasks/constraints/constraint_spec.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  mf::ConstraintSpec spec;
  try {
    spec = mf::ConstraintSpec::parse_json(text, "in.json");
  } catch (const mf::InputError& e) {
    MF_FUZZ_CHECK(std::string(e.what()).rfind("in.json", 0) == 0);
    return 0;
  }
  const std::string again = spec.to_json();
  MF_FUZZ_CHECK(mf::ConstraintSpec::parse_json(again, "again").to_json() == again);
  mf::Skeleton skel;
  skel.names = {"Hips", "Spine", "Head", "UpperLeg_L", "LowerLeg_L", "Foot_L", "Hand_R"};
  skel.parents = {-1, 0, 1, 0, 3, 4, 1};
  skel.offsets.assign(skel.names.size(), Eigen::Vector3d(0, 0.1, 0));
  try {
    const mf::MotionConstraints c = spec.resolve(skel, 0.01);
    c.validate(40, skel.num_joints());
  } catch (const mf::InputError&) {
  }
  return 0;
}
