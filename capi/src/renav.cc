// Re-navigation along a new ground path (tasks/renav/renav.h) and path CSV reading.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "capi/src/capi_internal.h"
#include "prior/runtime/nemf_runtime.h"
#include "prior/motion/errors.h"
#include "tasks/renav/renav.h"

using mf::capi::ApiError;
using mf::capi::guard;
using mf::capi::require;

extern "C" {

int mf_renav_options_init(mf_renav_options* options) {
  return guard([&] {
    require(options, "options");
    std::memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
  });
}

int mf_renav(const mf_model* model, const mf_motion* reference, const float* path_xz, size_t point_count,
             const mf_renav_options* renav, const mf_task_options* options, mf_motion** out) {
  return guard([&] {
    require(reference, "reference");
    require(out, "out");
    if (!path_xz && point_count != 0) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "path_xz is NULL");
    const mf_renav_options r = mf::capi::read_options(renav, "mf_renav_options");
    const mf_task_options o = mf::capi::read_options(options, "mf_task_options");
    if (r.path_kind != MF_PATH_PER_FRAME && r.path_kind != MF_PATH_POLYLINE)
      throw ApiError(MF_ERROR_INVALID_ARGUMENT, "mf_renav_options.path_kind must be MF_PATH_PER_FRAME or MF_PATH_POLYLINE, not " +
                                                    std::to_string(r.path_kind));
    if (r.path_kind == MF_PATH_PER_FRAME && r.frame_count != 0)
      throw ApiError(MF_ERROR_INVALID_ARGUMENT,
                     "mf_renav_options.frame_count applies to polylines only: a per-frame path has one point per frame");
    if (r.frame_count < 0 || r.frame_count == 1 || r.frame_count > mf::kMaxPathFrames)
      throw ApiError(MF_ERROR_INVALID_ARGUMENT, "mf_renav_options.frame_count must be 0 or 2 to " +
                                                    std::to_string(mf::kMaxPathFrames) + ", not " +
                                                    std::to_string(r.frame_count));
    if (!std::isfinite(r.fps) || r.fps < 0)
      throw ApiError(MF_ERROR_INVALID_ARGUMENT, "mf_renav_options.fps must be 0 (the reference's) or finite and positive");
    if (point_count > static_cast<size_t>(mf::kMaxPathFrames))
      throw ApiError(MF_ERROR_INVALID_ARGUMENT, "the path has more than " + std::to_string(mf::kMaxPathFrames) + " points");

    const mf::TaskContext ctx = mf::capi::task_context(model, o);
    const std::string method = o.method ? o.method : "";
    const mf::Motion& ref = reference->motion;

    std::vector<Eigen::Vector2d> path(point_count);
    for (size_t i = 0; i < point_count; ++i) path[i] = Eigen::Vector2d(path_xz[2 * i], path_xz[2 * i + 1]);
    mf::validate_path(path);
    const double fps = r.fps > 0 ? r.fps : ref.fps;
    if (r.path_kind == MF_PATH_POLYLINE) {
      const int frames =
          r.frame_count > 0 ? r.frame_count : mf::polyline_frame_count(path, mf::mean_ground_speed(ref), fps);
      path = mf::resample_polyline(path, frames);
    }
    const mf::capi::TaskThreads threads;
    mf::Motion result = mf::run_renav(ref, path, fps, method, ctx);
    *out = mf::capi::derived_motion(std::move(result), *reference);
  });
}

int mf_path_load_csv(const char* path, float* out, size_t capacity, size_t* needed) {
  return guard([&] {
    require(path, "path");
    const std::vector<Eigen::Vector2d> points = mf::read_path_csv(path);  // FileError: MF_ERROR_IO
    std::vector<float> flat(points.size() * 2);
    for (size_t i = 0; i < points.size(); ++i) {
      const float x = static_cast<float>(points[i].x()), z = static_cast<float>(points[i].y());
      if (!std::isfinite(x) || !std::isfinite(z))
        throw ApiError(MF_ERROR_INVALID_ARGUMENT,
                       std::string(path) + ": point " + std::to_string(i) + " does not fit in a float");
      flat[2 * i] = x;
      flat[2 * i + 1] = z;
    }
    mf::capi::write_buffer(flat.data(), flat.size(), out, capacity, needed);
  });
}

}  // extern "C"
