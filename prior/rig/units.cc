#include "prior/rig/units.h"

#include <algorithm>
#include <cmath>

#include "prior/motion/errors.h"
#include "prior/motion/motion_bvh.h"
#include "prior/rig/retarget.h"
#include "prior/rig/rig_map.h"

namespace mf {
namespace {

struct Candidate {
  const char* name;
  double metres;
  double penalty;
};
constexpr Candidate kUnits[] = {{"cm", 0.01, 0.0}, {"m", 1.0, 0.0},     {"mm", 0.001, 0.3},
                                {"in", 0.0254, 0.3}, {"ft", 0.3048, 0.5}, {"asf", 0.0254 / 0.45, 0.3}};
constexpr double kTypicalLeg = 0.85;  // metres, thigh to ankle

}  // namespace

LengthUnit length_unit_from_name(const std::string& name) {
  for (const Candidate& c : kUnits)
    if (name == c.name) return {c.name, c.metres};
  throw InputError("unknown length unit '" + name + "' (use cm, m, mm, in, ft or asf, or a number of metres per unit)");
}

LengthUnit detect_length_unit(const Skeleton& s, bool* detected) {
  const double leg = leg_length(s, find_rig_parts(s));
  if (detected) *detected = leg > 0;
  if (!(leg > 0) || !std::isfinite(leg)) return {"cm", 0.01};
  const Candidate* best = nullptr;
  double best_cost = 0;
  for (const Candidate& c : kUnits) {
    const double cost = std::abs(std::log(leg * c.metres / kTypicalLeg)) + c.penalty;
    if (!best || cost < best_cost) best = &c, best_cost = cost;
  }
  return {best->name, best->metres};
}

LengthUnit detect_bvh_length_unit(const BvhDocument& doc, bool* detected) {
  BvhDocument first;
  first.joints = doc.joints;
  first.num_frames = 1;
  first.frame_time = doc.frame_time;
  const size_t row = std::min(doc.values.size(), static_cast<size_t>(doc.num_channels()));
  first.values.assign(doc.values.begin(), doc.values.begin() + static_cast<std::ptrdiff_t>(row));
  BvhUnits file_units;
  file_units.length_scale = 1.0;
  return detect_length_unit(motion_from_bvh(first, file_units).skeleton, detected);
}

}  // namespace mf
