// How a motion's rig is read (its length unit) and mapped onto the model's.
#include <nlohmann/json.hpp>

#include "capi/src/capi_internal.h"
#include "prior/runtime/nemf_runtime.h"
#include "prior/motion/errors.h"
#include "prior/rig/retarget.h"
#include "prior/rig/rig_map.h"

namespace mf::capi {
namespace {

// The JSON text of mf_rig_describe (see motionfield.h).
std::string describe_rig(const mf_model& model, const mf_motion& motion, const std::string& map_json) {
  const Skeleton& user = motion.motion.skeleton;
  const Skeleton& rig = model.model->rig().skeleton;
  const RigMap map = map_rig(user, rig, map_json);
  nlohmann::ordered_json out;
  out["unit"] = motion.unit;
  out["length_scale"] = motion.length_scale;
  out["unit_detected"] = motion.unit_detected;
  out["unit_from_file"] = motion.unit_from_file;
  out["joints"] = user.num_joints();
  nlohmann::ordered_json mapped = nlohmann::ordered_json::object(), how = nlohmann::ordered_json::object();
  std::vector<bool> used(static_cast<size_t>(user.num_joints()), false);
  for (int m = 0; m < rig.num_joints(); ++m) {
    const int u = map.user_of_model[static_cast<size_t>(m)];
    if (u < 0) continue;
    used[static_cast<size_t>(u)] = true;
    mapped[user.names[static_cast<size_t>(u)]] = rig.names[static_cast<size_t>(m)];
    how[rig.names[static_cast<size_t>(m)]] = map.how[static_cast<size_t>(m)];
  }
  out["map"] = std::move(mapped);
  out["how"] = std::move(how);
  out["unmapped_user_joints"] = nlohmann::ordered_json::array();
  for (int u = 0; u < user.num_joints(); ++u)
    if (!used[static_cast<size_t>(u)]) out["unmapped_user_joints"].push_back(user.names[static_cast<size_t>(u)]);
  out["model_joints"] = rig.names;
  out["retargeting"] = model.model_anatomy != nullptr;
  out["anatomy"] = user.same_as(rig)                                 ? "model rig"
                   : rest_pose_is_t_or_a(user, map.user_parts) ? "rest pose"
                                                                     : "known frames";
  return out.dump();
}

}  // namespace
}  // namespace mf::capi

using mf::capi::ApiError;
using mf::capi::guard;
using mf::capi::require;

extern "C" {

int mf_rig_describe(const mf_model* model, const mf_motion* motion, const char* rig_map_json, char* out,
                    size_t capacity, size_t* needed) {
  return guard([&] {
    if (!model)
      throw ApiError(MF_ERROR_MODEL, "describing a rig needs a model (the rig to map onto), and none was given");
    require(motion, "motion");
    mf::capi::check_buffer_arguments(out, capacity, needed);  // before the mapping, which is not free
    const std::string text = mf::capi::describe_rig(*model, *motion, rig_map_json ? rig_map_json : "");
    mf::capi::write_string(text, out, capacity, needed);
  });
}

}  // extern "C"

extern "C" {

int mf_rig_map_read_file(const char* path, char* out, size_t capacity, size_t* needed) {
  return guard([&] {
    require(path, "path");
    mf::capi::check_buffer_arguments(out, capacity, needed);
    mf::capi::write_string(mf::read_rig_map_file(path), out, capacity, needed);  // FileError: MF_ERROR_IO
  });
}

}  // extern "C"
