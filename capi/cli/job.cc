#include "job.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "input_error.h"

namespace motionfield::cli {
namespace {

using Clock = std::chrono::steady_clock;

// Fails before any work when the output cannot be written (the C API would
// only find out after the solve).
void check_output_path(const std::string& out) {
  namespace fs = std::filesystem;
  const fs::path p(out);
  std::error_code ec;
  if (fs::is_directory(p, ec)) throw InputError("cannot write " + out + ": it is a directory");
  const fs::path dir = p.parent_path();
  if (!dir.empty() && !fs::is_directory(dir, ec))
    throw InputError("cannot write " + out + ": directory " + dir.string() + " does not exist");
}

// What a job checks before reading anything: its method exists, re-navigation's numbers, the output path.
void check_job(const BatchJob& job) {
  const bool renav = job.task == "renav";
  // Re-navigation has methods of its own, checked by mf_renav.
  if (!job.method.empty() && !renav) find_method(job.method);
  if (renav) {
    if (job.fps < 0 || !std::isfinite(job.fps)) throw InputError("renav: the fps must be positive");
    if (job.polyline && job.frames != 0 && job.frames < 2)
      throw InputError("renav: the frame count must be at least 2");
  }
  check_output_path(job.out);
}

Motion solve(const BatchJob& job, const Settings& settings, const Model& model, const Motion& input) {
  TaskOptions options(job.method);
  options.rig_map_path = job.rig_map.empty() ? settings.rig_map : job.rig_map;
  if (job.task == "inbetween" || (job.task == "fill" && job.has_keyframes))
    return inbetween(model, input, std::vector<int32_t>(job.keyframes.begin(), job.keyframes.end()), options);
  if (job.task == "fill") return fill(model, input, job.gap_begin, job.gap_end, options);
  if (job.task == "resample") return resample(model, input, job.fps, options);
  if (job.task == "renav") {
    RenavOptions renav_options;
    renav_options.path_kind = job.polyline ? MF_PATH_POLYLINE : MF_PATH_PER_FRAME;
    renav_options.fps = job.fps;
    if (job.polyline) renav_options.frame_count = job.frames;
    return renav(model, input, load_path_csv(job.path_file), renav_options, options);
  }
  throw InputError("unknown task '" + job.task + "'");
}

// The method that ran, for --verbose.
std::string method_name(const BatchJob& job, const Model& model) {
  if (!job.method.empty()) return job.method;
  if (job.task == "resample") return "default";
  if (job.task == "renav") return "nemf";
  return default_method(model);
}

}  // namespace

std::string run_job(const BatchJob& job, const Settings& settings, Models& models) {
  const auto t0 = Clock::now();
  check_job(job);
  // Re-navigation always needs the prior, whatever the method.
  const Model& model = models.for_method(job.task == "renav" && job.method.empty() ? "nemf" : job.method);
  const Motion input = Motion::load_bvh(job.in, units_scale(job.units.empty() ? settings.units : job.units, "--units"));
  const auto t1 = Clock::now();
  const Motion result = solve(job, settings, model, input);
  const auto t2 = Clock::now();
  result.save_bvh(job.out);
  const auto t3 = Clock::now();

  if (settings.verbose) {
    auto ms = [](Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); };
    std::fprintf(stderr,
                 "motionfield: %s %s -> %s: %d -> %d frames, method %s, model %s, %d threads; read %.1f ms, "
                 "solve %.1f ms, write %.1f ms\n",
                 job.task.c_str(), job.in.c_str(), job.out.c_str(), input.frame_count(), result.frame_count(),
                 method_name(job, model).c_str(), model ? models.path().c_str() : "none", settings.threads, ms(t1 - t0),
                 ms(t2 - t1), ms(t3 - t2));
  }
  return result.warnings();
}

}  // namespace motionfield::cli
