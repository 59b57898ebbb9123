#include "capi/src/jobs/runner.h"

#include <utility>


namespace motionfield::jobs {
namespace {

// A job's label in a batch: "<batch> line N".
CheckedJob unchecked(size_t line, const std::string& batch_path, bool single) {
  CheckedJob c;
  c.line = single ? 0 : line;
  if (!single) c.label = batch_path + " line " + std::to_string(line);
  return c;
}

// The model a job asks for by its method ("" = the default method).
std::string model_method(const BatchJob& job) { return job.task == "renav" && job.method.empty() ? "nemf" : job.method; }

}  // namespace

JobRunner::JobRunner(JobSettings settings, bool preload)
    : settings_(std::move(settings)),
      preload_(preload),
      models_(settings_.model, settings_.transformers),
      batch_files_(OutputSet::create()) {
  models_.load_explicit();
}

// The job of one line and its files; the label gains the job's id once the line parses.
void JobRunner::parse(const std::string& text, bool single, CheckedJob* c) const {
  JsonValue value;
  try {
    value = parse_json(text);
  } catch (const JsonError& e) {
    throw InputError(std::string("invalid JSON: ") + e.what());
  }
  const JsonValue* id = value.find("id");
  if (id && !single) c->label += " (id " + (id->is_string() ? id->as_string() : id->dump()) + ")";
  c->job = batch_job_from_json(value, single);
  if (!single && (c->job.in == "-" || c->job.out == "-"))
    throw InputError("\"-\" (standard input or output) is for single commands, not batch jobs");
  c->files = prepare_job(c->job, settings_);
}

CheckedJob JobRunner::check_line(const std::string& text, size_t line, const std::string& batch_path) {
  CheckedJob c = unchecked(line, batch_path, false);
  const std::lock_guard<std::mutex> lock(mutex_);
  try {
    parse(text, false, &c);
    batch_files_.merge(c.files, "line " + std::to_string(line));
    if (preload_) models_.for_method(model_method(c.job));
    c.runnable = true;
    c.load_warnings = c.job.method.empty() && !load_warnings_given_;
    load_warnings_given_ = load_warnings_given_ || c.load_warnings;
  } catch (...) {
    c.failure = current_failure();
  }
  return c;
}

JobResult JobRunner::run(CheckedJob c, const ProgressFn& progress) {
  if (!c.runnable) return outcome(c, nullptr, &c.failure);
  try {
    const JobReport report = run_job(c.job, std::move(c.files), settings_, models_, progress, c.load_warnings);
    return outcome(c, &report, nullptr);
  } catch (...) {
    const Failure failure = current_failure();
    return outcome(c, nullptr, &failure);
  }
}

JobResult JobRunner::run_line(const std::string& text, size_t line, const std::string& batch_path, bool single,
                              bool load_warnings, const ProgressFn& progress) {
  CheckedJob c = unchecked(line, batch_path, single);
  try {
    parse(text, single, &c);
    c.runnable = true;
    c.load_warnings = load_warnings;
  } catch (...) {
    c.failure = current_failure();
  }
  return run(std::move(c), progress);
}

const Model& JobRunner::load_model() { return models_.for_method(""); }

JobResult JobRunner::outcome(const CheckedJob& c, const JobReport* report, const Failure* failure) const {
  JobResult r;
  const std::string prefix = c.label.empty() ? "" : c.label + ": ";
  if (report) {
    if (!report->verbose.empty()) r.messages += "motionfield: " + printable(report->verbose) + "\n";
    if (!settings_.quiet) r.messages += warning_lines(report->warnings, prefix);
    r.json = job_json(c.job, report, nullptr, c.line);
    return r;
  }
  r.exit_code = failure->exit_code;
  r.messages = failure_line(*failure, prefix);
  Failure shown = *failure;
  shown.message = printable(failure->message);
  r.json = job_json(c.job, nullptr, &shown, c.line);
  return r;
}

BatchSummary batch_summary(const std::string& batch_path, const std::vector<int>& exit_codes, uint32_t flags) {
  const int total = static_cast<int>(exit_codes.size());
  int bad = 0, internal = 0;
  for (int code : exit_codes)
    if (code != kExitOk) ++(code == kExitBadInput ? bad : internal);
  const int failed = bad + internal;
  BatchSummary s;
  s.exit_code = internal > 0 ? kExitInternal : bad > 0 ? kExitBadInput : kExitOk;
  const bool progress = (flags & MF_JOB_PROGRESS_SHOWN) && !(flags & MF_JOB_QUIET);
  if (failed > 0 || (flags & MF_JOB_VERBOSE) || progress)
    s.line = "motionfield: " +
             printable("batch " + batch_path + ": " + std::to_string(total) + " jobs, " +
                       std::to_string(total - failed) + " ok, " + std::to_string(failed) + " failed") +
             "\n";
  return s;
}

}  // namespace motionfield::jobs
