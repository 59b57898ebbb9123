// The tasks: in-betweening, gap filling, resampling (tasks/methods/jobs.h by method
// name), and the task context every task (re-navigation too) runs in.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "capi/src/capi_internal.h"
#include "prior/motion/errors.h"
#include "prior/rig/rig_map.h"
#include "tasks/methods/jobs.h"

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
  return read_rig_map_file(file);  // FileError: MF_ERROR_IO
}

}  // namespace

TaskContext task_context(const mf_model* model, const mf_task_options& o) {
  TaskContext ctx;
  if (model) static_cast<ModelSet&>(ctx) = *model;
  ctx.seed = o.seed;
  if (o.max_iterations < 0)
    throw ApiError(MF_ERROR_INVALID_ARGUMENT,
                   "mf_task_options.max_iterations is " + std::to_string(o.max_iterations) + ": must be >= 0");
  ctx.max_iterations = o.max_iterations;
  ctx.interpolation_fallback = o.no_fallback == 0;
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
      cp.window = p.window;
      cp.window_count = p.window_count;
      return fn(user_data, &cp) == 0;
    };
  }
  if (o.cancel) ctx.cancel = &o.cancel->flag;
  ctx.rig_map = rig_map_of(o);
  ctx.rig_map_source = rig_map_file(o);
  return ctx;
}

namespace {

// Runs one task: the C boundary checks what C callers can get wrong (NULL
// pointers, the options struct); the library validates the request itself.
// `run(input, method, ctx, warnings)` returns the result and may append
// warnings for the caller, which the result handle carries.
template <class Run>
int run_task(const mf_model* model, const mf_motion* input, const mf_task_options* options, mf_motion** out,
             Run&& run) {
  return guard([&] {
    require(input, "input");
    require(out, "out");
    const mf_task_options o = read_options(options, "mf_task_options");
    const TaskContext ctx = task_context(model, o);
    const TaskThreads threads;
    std::vector<std::string> warnings;
    Motion result = run(input->motion, o.method ? std::string(o.method) : std::string(), ctx, &warnings);
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
                                std::vector<std::string>* warnings) {
                              if (!keyframes && keyframe_count != 0)
                                throw ApiError(MF_ERROR_INVALID_ARGUMENT, "keyframes is NULL");
                              const std::vector<int> keys(keyframes, keyframes + keyframe_count);
                              return mf::run_inbetween(in, keys, method, ctx, warnings);
                            });
}

int mf_fill(const mf_model* model, const mf_motion* input, int32_t gap_begin, int32_t gap_end,
            const mf_task_options* options, mf_motion** out) {
  return mf::capi::run_task(model, input, options, out,
                            [&](const mf::Motion& in, const std::string& method, const mf::TaskContext& ctx,
                                std::vector<std::string>* warnings) {
                              return mf::run_fill(in, gap_begin, gap_end, method, ctx, warnings);
                            });
}

int mf_resample(const mf_model* model, const mf_motion* input, double fps, const mf_task_options* options,
                mf_motion** out) {
  return mf::capi::run_task(model, input, options, out,
                            [&](const mf::Motion& in, const std::string& method, const mf::TaskContext& ctx,
                                std::vector<std::string>* warnings) {
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
