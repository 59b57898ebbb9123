// The length unit of a motion file, detected from its skeleton or named by the
// caller. BVH carries no unit; the rig's leg length (thigh to ankle) tells it:
// an adult's is about 0.85 m, so 85 reads as centimetres, 0.85 as metres, 33 as
// inches and 15 as CMU's ASF unit (1/0.45 inch).
#pragma once

#include <string>

#include "prior/motion/bvh.h"
#include "prior/motion/skeleton.h"

namespace mf {

struct LengthUnit {
  std::string name;     ///< "cm", "m", "mm", "in", "ft" or "asf"
  double metres = 0.0;  ///< metres per file unit
};

/// Metres per unit of a unit name: "cm", "m", "mm", "in" (inches), "ft", "asf"
/// (CMU's ASF/AMC length unit, 1/0.45 inch = 0.05644 m). Throws InputError on
/// any other name, listing these.
LengthUnit length_unit_from_name(const std::string& name);

/// The unit that makes the skeleton's leg length (offsets in file units) most
/// like a person's (0.85 m), preferring centimetres and metres, the common
/// cases, over the others (their log-distance is penalised by 0.3). A skeleton
/// without legs the rig map can find gives centimetres (the BVH default) and
/// `detected` false.
LengthUnit detect_length_unit(const Skeleton& skeleton_in_file_units, bool* detected = nullptr);

/// detect_length_unit() of a BVH document's skeleton in file units (read from
/// its first frame: position channels on non-root joints replace offsets).
LengthUnit detect_bvh_length_unit(const BvhDocument& doc, bool* detected = nullptr);

}  // namespace mf
