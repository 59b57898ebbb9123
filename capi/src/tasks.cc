// The tasks: in-betweening, gap filling, resampling (tasks/jobs.h by method
// name), and the task context every task (re-navigation too) runs in.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "capi/src/capi_internal.h"
#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/rig/rig_map.h"
#include "tasks/jobs.h"
#include "tasks/model_rig.h"

namespace mf::capi {
namespace {

// The rig map file of the options, or "" when none.
std::string rig_map_file(const mf_task_options& o) { return o.rig_map_path ? o.rig_map_path : ""; }

// The rig map text of the options (read from the file if one is named); ""
// for the automatic map.
std::string rig_map_of(const mf_task_options& o) {
  const std::string file = rig_map_file(o);
  const bool text = o.rig_map && *o.rig_map;
  if (text && !file.empty())
    throw ApiError(MF_ERROR_INVALID_ARGUMENT, "mf_task_options: give rig_map or rig_map_path, not both");
  if (text) return o.rig_map;
  if (file.empty()) return "";
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec) || !std::ifstream(file, std::ios::binary))
    throw ApiError(MF_ERROR_IO, file + ": cannot open the rig map file");
  return read_rig_map_file(file);
}

}  // namespace

TaskContext task_context(const mf_model* model, const mf_task_options& o) {
  TaskContext ctx;
  set_models(model, &ctx);
  ctx.seed = o.seed;
  if (o.progress) {
    const mf_progress_fn fn = o.progress;
    void* const user_data = o.user_data;
    ctx.progress = [fn, user_data](const TaskProgress& p) {
      mf_progress cp;
      std::memset(&cp, 0, sizeof cp);
      cp.struct_size = sizeof cp;
      cp.iteration = p.iteration;
      cp.max_iterations = p.max_iterations;
      cp.energy = p.energy;
      return fn(user_data, &cp) == 0;
    };
  }
  if (o.cancel) ctx.cancel = &o.cancel->flag;
  ctx.rig_map = rig_map_of(o);
  return ctx;
}

void check_model_rig(const mf_model* model, const Skeleton& input, const mf_task_options& o, const TaskContext& ctx) {
  if (!ctx.model || input.same_as(ctx.model->rig().skeleton)) return;
  if (!ctx.model_anatomy) {
    const std::string why = model && !model->anatomy_error.empty()
                                ? "the model's rig anatomy file did not load: " + model->anatomy_error
                                : std::string("the model has no rig anatomy to retarget with (") + kRigAnatomyFileName +
                                      " next to the model file)";
    throw ApiError(model && !model->anatomy_error.empty() ? MF_ERROR_MODEL : MF_ERROR_INVALID_ARGUMENT,
                   "the motion has " + std::to_string(input.num_joints()) +
                       " joints on another rig than the model's (" + std::to_string(ctx.model->rig().num_joints()) +
                       " joints), and " + why);
  }
  try {
    model_rig_map(input, ctx);
  } catch (const InputError& e) {
    const std::string file = rig_map_file(o);
    throw ApiError(MF_ERROR_INVALID_ARGUMENT, (file.empty() ? "" : file + ": ") + e.what());
  }
}

namespace {

// The context of one task call from its options; checks what the C boundary
// can check before the method runs.
TaskContext make_context(const mf_model* model, const mf_motion& input, const mf_task_options& o,
                         std::string* method) {
  const TaskContext ctx = task_context(model, o);
  *method = o.method ? o.method : "";
  const std::string name = method->empty() ? default_method(ctx) : *method;
  const Method* found = nullptr;
  std::string list;
  for (const Method& m : registered_methods()) {
    list += (list.empty() ? "" : ", ") + m.name;
    if (m.name == name) found = &m;
  }
  if (!found) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "unknown method '" + name + "' (available: " + list + ")");
  if (found->needs_model) {
    if (!ctx.model)
      throw ApiError(MF_ERROR_MODEL, "method '" + name + "' needs a model (the prior), and none was given");
    check_model_rig(model, input.motion.skeleton, o, ctx);
  }
  require_inbetweener(model, name, found->needs_inbetweener);
  return ctx;
}

// Called by each task once its arguments are validated: the first progress
// report, which also honours a cancel token cancelled before the call.
void start(const TaskContext& ctx) { ctx.report(TaskProgress{}); }

// `run(input, method, ctx, warnings)` returns the result and may append
// warnings for the caller, which the result handle carries.
template <class Run>
int run_task(const mf_model* model, const mf_motion* input, const mf_task_options* options, mf_motion** out,
             Run&& run) {
  return guard([&] {
    require(input, "input");
    require(out, "out");
    const mf_task_options o = read_options(options, "mf_task_options");
    std::string method;
    const TaskContext ctx = make_context(model, *input, o, &method);
    apply_num_threads();
    std::vector<std::string> warnings;
    Motion result = run(input->motion, method, ctx, &warnings);
    std::unique_ptr<mf_motion> handle(derived_motion(std::move(result), *input));
    for (const std::string& w : warnings) handle->warnings += (handle->warnings.empty() ? "" : "\n") + w;
    *out = handle.release();
  });
}

}  // namespace
}  // namespace mf::capi

using mf::capi::ApiError;
using mf::capi::guard;
using mf::capi::require;

extern "C" {

int mf_inbetween(const mf_model* model, const mf_motion* input, const int32_t* keyframes, size_t keyframe_count,
                 const mf_task_options* options, mf_motion** out) {
  return mf::capi::run_task(model, input, options, out,
                            [&](const mf::Motion& in, const std::string& method, const mf::TaskContext& ctx,
                                std::vector<std::string>*) {
                              if (!keyframes && keyframe_count != 0)
                                throw ApiError(MF_ERROR_INVALID_ARGUMENT, "keyframes is NULL");
                              const std::vector<int> keys(keyframes, keyframes + keyframe_count);
                              mf::validate_keyframes(keys, in.num_frames());
                              mf::capi::start(ctx);
                              return mf::run_inbetween(in, keys, method, ctx);
                            });
}

int mf_fill(const mf_model* model, const mf_motion* input, int32_t gap_begin, int32_t gap_end,
            const mf_task_options* options, mf_motion** out) {
  return mf::capi::run_task(model, input, options, out,
                            [&](const mf::Motion& in, const std::string& method, const mf::TaskContext& ctx,
                                std::vector<std::string>*) {
                              mf::known_frames_outside_gap(in.num_frames(), gap_begin, gap_end);
                              mf::capi::start(ctx);
                              return mf::run_fill(in, gap_begin, gap_end, method, ctx);
                            });
}

int mf_resample(const mf_model* model, const mf_motion* input, double fps, const mf_task_options* options,
                mf_motion** out) {
  return mf::capi::run_task(model, input, options, out,
                            [&](const mf::Motion& in, const std::string& method, const mf::TaskContext& ctx,
                                std::vector<std::string>* warnings) {
                              if (!(std::isfinite(fps) && fps > 0))
                                throw ApiError(MF_ERROR_INVALID_ARGUMENT, "the target fps must be finite and positive");
                              mf::resampled_frame_count(in.num_frames(), in.fps, fps, nullptr);
                              mf::capi::start(ctx);
                              return mf::run_resample(in, fps, method, warnings, ctx);
                            });
}

int mf_resample_frame_count(int32_t frame_count, double fps_in, double fps_out, int32_t* out, int32_t* rounded) {
  return guard([&] {
    require(out, "out");
    bool r = false;
    const int n = mf::resampled_frame_count(frame_count, fps_in, fps_out, &r);
    *out = n;
    if (rounded) *rounded = r ? 1 : 0;
  });
}

}  // extern "C"
