// mf_job_runner, mf_job and mf_job_result (motionfield.h, "batch jobs"): the
// C side of JobRunner.
#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "capi/src/capi_internal.h"
#include "capi/src/jobs/runner.h"

struct mf_job_runner {
  std::unique_ptr<motionfield::jobs::JobRunner> runner;
};

struct mf_job {
  motionfield::jobs::CheckedJob job;
  bool spent = false;
};

struct mf_job_result {
  motionfield::jobs::JobResult result;
};

namespace mf::capi {

template <>
struct OptionPointerFields<mf_job_runner_options> {
  static constexpr size_t offsets[4] = {offsetof(mf_job_runner_options, model),
                                        offsetof(mf_job_runner_options, inbetweeners),
                                        offsetof(mf_job_runner_options, rig_map), offsetof(mf_job_runner_options, units)};
  static constexpr size_t count = 4;
};
template <>
struct OptionPointerFields<mf_job_run_options> {
  static constexpr size_t offsets[2] = {offsetof(mf_job_run_options, progress),
                                        offsetof(mf_job_run_options, user_data)};
  static constexpr size_t count = 2;
};

namespace {

namespace jobs = motionfield::jobs;

// guard() for bodies written against motionfield.hpp: its Error (and
// InputError) becomes the status it stands for.
template <class Body>
int job_guard(Body&& body) noexcept {
  return guard([&] {
    try {
      body();
    } catch (const motionfield::Error& e) {
      throw ApiError(e.status(), e.what());
    }
  });
}

std::string text_of(const char* text, size_t length) {
  if (!text && length != 0) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "text is NULL");
  return text ? std::string(text, length) : std::string();
}

jobs::JobSettings settings_of(const mf_job_runner_options& o) {
  if (o.inbetweener_count > 0) require(o.inbetweeners, "options->inbetweeners");
  if (o.threads < 0) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "options->threads is negative");
  jobs::JobSettings s;
  s.threads = o.threads > 0 ? o.threads : 1;
  s.verbose = (o.flags & MF_JOB_VERBOSE) != 0;
  s.quiet = (o.flags & MF_JOB_QUIET) != 0;
  s.model = o.model ? o.model : "";
  for (size_t i = 0; i < o.inbetweener_count; ++i) {
    require(o.inbetweeners[i], "options->inbetweeners[i]");
    s.transformers.emplace_back(o.inbetweeners[i]);
  }
  s.rig_map = o.rig_map ? o.rig_map : "";
  s.units = o.units ? o.units : "";
  // A bad default unit is the run's error, before any job.
  motionfield::units_scale(s.units, "--units (--length-scale)");
  return s;
}

jobs::ProgressFn progress_of(const mf_job_run_options& o) {
  if (!o.progress) return {};
  return [fn = o.progress, user = o.user_data](const mf_progress& p) { return fn(user, &p) == 0; };
}

mf_job_result* new_result(jobs::JobResult result) {
  auto handle = std::make_unique<mf_job_result>();
  handle->result = std::move(result);
  return handle.release();
}

const jobs::JobResult& get(const mf_job_result* result) {
  require(result, "result");
  return result->result;
}

}  // namespace
}  // namespace mf::capi

using mf::capi::ApiError;
using mf::capi::job_guard;
using mf::capi::require;

extern "C" {

int mf_job_runner_options_init(mf_job_runner_options* options) {
  return job_guard([&] {
    require(options, "options");
    *options = mf::capi::read_options<mf_job_runner_options>(nullptr, "mf_job_runner_options");
  });
}

int mf_job_runner_create(const mf_job_runner_options* options, mf_job_runner** out) {
  return job_guard([&] {
    require(out, "out");
    const auto o = mf::capi::read_options(options, "mf_job_runner_options");
    auto handle = std::make_unique<mf_job_runner>();
    handle->runner = std::make_unique<motionfield::jobs::JobRunner>(mf::capi::settings_of(o),
                                                                    (o.flags & MF_JOB_PRELOAD_MODEL) != 0);
    *out = handle.release();
  });
}

void mf_job_runner_destroy(mf_job_runner* runner) { delete runner; }

int mf_job_runner_check_line(mf_job_runner* runner, const char* text, size_t length, uint64_t line_number,
                             const char* batch_path, mf_job** out) {
  return job_guard([&] {
    require(runner, "runner");
    require(batch_path, "batch_path");
    require(out, "out");
    const std::string line = mf::capi::text_of(text, length);
    auto handle = std::make_unique<mf_job>();
    handle->job = runner->runner->check_line(line, static_cast<size_t>(line_number), batch_path);
    *out = handle.release();
  });
}

int mf_job_is_runnable(const mf_job* job) { return job && job->job.runnable && !job->spent ? 1 : 0; }

int mf_job_has_load_warnings(const mf_job* job) { return job && job->job.load_warnings ? 1 : 0; }

void mf_job_destroy(mf_job* job) { delete job; }

int mf_job_run_options_init(mf_job_run_options* options) {
  return job_guard([&] {
    require(options, "options");
    *options = mf::capi::read_options<mf_job_run_options>(nullptr, "mf_job_run_options");
  });
}

int mf_job_run(mf_job_runner* runner, mf_job* job, const mf_job_run_options* options, mf_job_result** out) {
  return job_guard([&] {
    require(runner, "runner");
    require(job, "job");
    require(out, "out");
    const auto o = mf::capi::read_options(options, "mf_job_run_options");
    if (job->spent) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "the job has run already");
    job->spent = true;
    *out = mf::capi::new_result(runner->runner->run(std::move(job->job), mf::capi::progress_of(o)));
  });
}

int mf_job_runner_run_line(mf_job_runner* runner, const char* text, size_t length, uint64_t line_number,
                           const char* batch_path, const mf_job_run_options* options, mf_job_result** out) {
  return job_guard([&] {
    require(runner, "runner");
    require(batch_path, "batch_path");
    require(out, "out");
    const auto o = mf::capi::read_options(options, "mf_job_run_options");
    const std::string line = mf::capi::text_of(text, length);
    *out = mf::capi::new_result(runner->runner->run_line(line, static_cast<size_t>(line_number), batch_path,
                                                         (o.flags & MF_JOB_SINGLE) != 0,
                                                         (o.flags & MF_JOB_LOAD_WARNINGS) != 0,
                                                         mf::capi::progress_of(o)));
  });
}

int mf_job_runner_load_model(mf_job_runner* runner, mf_model** out) {
  return job_guard([&] {
    require(runner, "runner");
    const motionfield::Model& model = runner->runner->load_model();
    if (out) *out = model ? new mf_model(*model.get()) : nullptr;
  });
}

int mf_job_runner_get_model_path(const mf_job_runner* runner, char* out, size_t capacity, size_t* needed) {
  return job_guard([&] {
    require(runner, "runner");
    mf::capi::write_string(runner->runner->model_path(), out, capacity, needed);
  });
}

void mf_job_result_destroy(mf_job_result* result) { delete result; }

int mf_job_result_get_exit_code(const mf_job_result* result, int32_t* out) {
  return job_guard([&] {
    const motionfield::jobs::JobResult& r = mf::capi::get(result);
    require(out, "out");
    *out = r.exit_code;
  });
}

int mf_job_result_get_messages(const mf_job_result* result, char* out, size_t capacity, size_t* needed) {
  return job_guard([&] { mf::capi::write_string(mf::capi::get(result).messages, out, capacity, needed); });
}

int mf_job_result_get_json(const mf_job_result* result, char* out, size_t capacity, size_t* needed) {
  return job_guard([&] { mf::capi::write_string(mf::capi::get(result).json, out, capacity, needed); });
}

int mf_job_batch_summary(const char* batch_path, const int32_t* exit_codes, size_t count, uint32_t flags,
                         int32_t* exit_code, char* out, size_t capacity, size_t* needed) {
  return job_guard([&] {
    require(batch_path, "batch_path");
    if (count > 0) require(exit_codes, "exit_codes");
    const motionfield::BatchSummary s =
        motionfield::jobs::batch_summary(batch_path, std::vector<int>(exit_codes, exit_codes + count), flags);
    if (exit_code) *exit_code = s.exit_code;
    mf::capi::write_string(s.line, out, capacity, needed);
  });
}

}  // extern "C"
