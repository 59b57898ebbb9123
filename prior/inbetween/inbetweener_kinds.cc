#include "prior/inbetween/inbetweener_kinds.h"

#include "prior/inbetween/inbetween_config.h"
#include "prior/motion/errors.h"

namespace mf {

const std::vector<InbetweenerKind>& inbetweener_kinds() {
  static const std::vector<InbetweenerKind> kinds = {
      {kTwoStageKind,
       "two-stage transformer",
       "motionfield-twostage.mfm",
       {{"context", "Context Transformer only"}, {"detail", "Context + Detail Transformer"}},
       /*reads_trajectory=*/false,
       /*locks_feet=*/true},
      {kCitlKind, "CITL transformer", "motionfield-citl.mfm", {{"citl", "CITL transformer"}}},
      {kKeyframeKind,
       "keyframe transformer (KeyframeNet + RefineNet)",
       "motionfield-keyframe.mfm",
       {{"keyframe", "KeyframeNet's keyframes, interpolated"},
        {"refine", "KeyframeNet + RefineNet (trajectory-conditioned)"}},
       /*reads_trajectory=*/true,
       /*locks_feet=*/true},
  };
  return kinds;
}

const InbetweenerKind* find_inbetweener_kind(const std::string& name) {
  for (const InbetweenerKind& k : inbetweener_kinds()) {
    if (k.name == name) return &k;
  }
  return nullptr;
}

const InbetweenerKind* find_inbetweener_stage(const std::string& stage, int* index) {
  for (const InbetweenerKind& k : inbetweener_kinds()) {
    for (size_t i = 0; i < k.stages.size(); ++i) {
      if (k.stages[i].name != stage) continue;
      if (index) *index = static_cast<int>(i);
      return &k;
    }
  }
  return nullptr;
}

const InbetweenerKind& inbetweener_kind(const std::string& name) {
  if (const InbetweenerKind* k = find_inbetweener_kind(name)) return *k;
  std::string list;
  for (const InbetweenerKind& k : inbetweener_kinds()) list += (list.empty() ? "" : ", ") + k.name;
  throw InputError("unknown in-betweener kind '" + name + "' (available: " + list + ")");
}

}  // namespace mf
