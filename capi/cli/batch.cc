// `motionfield batch JOBS.jsonl [--jobs N]`: one job per line, each failure
// reported with its line, the others still run; N jobs at once on one model.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "commands.h"
#include "input_error.h"
#include "job.h"
#include "jsonl.h"
#include "models.h"
#include "progress.h"

namespace motionfield::cli {
namespace {

bool blank(const std::string& line) { return line.find_first_not_of(" \t\r\n") == std::string::npos; }

std::vector<std::string> read_lines(const std::string& path) {
  std::istringstream text(read_text_file(path, "batch file"));
  std::vector<std::string> lines;
  for (std::string line; std::getline(text, line);) lines.push_back(line);
  if (!lines.empty() && lines[0].compare(0, 3, "\xEF\xBB\xBF") == 0) lines[0].erase(0, 3);  // UTF-8 BOM
  return lines;
}

// The job of one line; `label` gains the job's id once the line parses.
BatchJob parse_line(const std::string& line, std::string* label) {
  JsonValue value;
  try {
    value = parse_json(line);
  } catch (const JsonError& e) {
    throw InputError(std::string("invalid JSON: ") + e.what());
  }
  if (const JsonValue* id = value.find("id"))
    *label += " (id " + (id->is_string() ? id->as_string() : id->dump()) + ")";
  BatchJob job = batch_job_from_json(value);
  if (job.in == "-" || job.out == "-")
    throw InputError("\"-\" (standard input or output) is for single commands, not batch jobs");
  return job;
}

// One line's job once run: its report, or why it failed.
struct Outcome {
  size_t line = 0;        ///< 1-based
  bool runnable = false;  ///< parsed and its files checked
  std::string label;
  BatchJob job;
  OutputSet files;  ///< the job's files, checked (prepare_job)
  bool ok = false;
  JobReport report;
  Failure failure;
};

// Prints what a finished line says (warnings or the failure; its --json line).
void print_outcome(const Outcome& o, size_t line, const Settings& settings) {
  if (o.ok) {
    if (!settings.quiet) print_warnings(o.report.warnings, o.label + ": ");
    if (settings.json) std::printf("%s\n", job_json(o.job, &o.report, nullptr, line).c_str());
  } else {
    print_failure(o.failure, o.label + ": ");
    if (settings.json) {
      Failure shown = o.failure;
      shown.message = printable(o.failure.message);
      std::printf("%s\n", job_json(o.job, nullptr, &shown, line).c_str());
    }
  }
  if (settings.json) std::fflush(stdout);
}

// --jobs, else one job per core's worth of --threads: jobs side by side use
// the cores better than threads inside one job (docs/BENCHMARKS.md, "Threads":
// a 128-frame solve is only 3-20 % faster on two threads of an idle machine,
// and far slower when the cores are busy).
// At most 8 by default: every job holds its own solver's tensors.
int batch_workers(const Settings& settings) {
  if (settings.jobs > 0) return settings.jobs;
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return std::clamp(cores / std::max(1, settings.threads), 1, 8);
}

// Every line parsed and its files checked first, in line order, against its
// own and every earlier line's (so that which of two jobs writing one file,
// or writing what another reads, is refused does not depend on timing); with
// `load_models`, the model a job needs is loaded here too, once, before any
// worker runs.
std::vector<Outcome> prepare_lines(const std::vector<std::string>& lines, const std::string& path,
                                   const Settings& settings, Models& models, bool load_models) {
  std::vector<Outcome> outcomes;
  OutputSet batch_files = OutputSet::create();
  for (size_t i = 0; i < lines.size(); ++i) {
    if (blank(lines[i])) continue;
    Outcome o;
    o.line = i + 1;
    o.label = path + " line " + std::to_string(o.line);
    try {
      o.job = parse_line(lines[i], &o.label);
      o.files = prepare_job(o.job, settings);
      batch_files.merge(o.files, "line " + std::to_string(o.line));
      if (load_models) models.for_method(o.job.task == "renav" && o.job.method.empty() ? "nemf" : o.job.method);
      o.runnable = true;
    } catch (...) {
      o.failure = current_failure();
    }
    outcomes.push_back(std::move(o));
  }
  return outcomes;
}

}  // namespace

int command_batch(const std::string& path, const Settings& settings) {
  const std::vector<std::string> lines = read_lines(path);
  Models models(settings.model, settings.transformers());
  models.load_explicit();
  const int workers = batch_workers(settings);
  if (settings.verbose) std::fprintf(stderr, "motionfield: batch: %d job%s at once\n", workers, workers == 1 ? "" : "s");

  std::vector<Outcome> outcomes = prepare_lines(lines, path, settings, models, workers > 1);
  const int total = static_cast<int>(outcomes.size());

  ProgressLine progress(ProgressLine::stderr_is_terminal() && !settings.quiet);
  const auto run = [&](size_t k, ProgressLine& line) {
    if (!outcomes[k].runnable) return;
    try {
      outcomes[k].report = run_job(outcomes[k].job, std::move(outcomes[k].files), settings, models, line);
      outcomes[k].ok = true;
    } catch (...) {
      outcomes[k].failure = current_failure();
    }
    line.clear();
  };
  if (workers <= 1) {
    for (size_t k = 0; k < outcomes.size(); ++k) {
      progress.start("[" + std::to_string(k + 1) + "/" + std::to_string(total) + "] line " + std::to_string(outcomes[k].line));
      run(k, progress);
      print_outcome(outcomes[k], outcomes[k].line, settings);
    }
  } else {
    // Workers share the model (the C API's tasks are thread-safe on one model);
    // each line's messages are printed in line order as soon as every earlier
    // line has finished, so the output is the serial run's.
    std::atomic<size_t> next{0};
    std::mutex mutex;
    std::vector<char> finished(outcomes.size(), 0);
    size_t printed = 0, done = 0;
    const auto started = std::chrono::steady_clock::now();
    const auto jobs_done = [&] {
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      progress.show("[" + std::to_string(done) + "/" + std::to_string(total) + " jobs done, " +
                    std::to_string(workers) + " at once] " + std::to_string(std::lround(s)) + "s");
    };
    jobs_done();
    const auto worker = [&] {
      ProgressLine silent(false);
      for (size_t k; (k = next++) < outcomes.size();) {
        run(k, silent);
        const std::lock_guard<std::mutex> lock(mutex);
        finished[k] = 1;
        ++done;
        progress.clear();
        for (; printed < outcomes.size() && finished[printed]; ++printed)
          print_outcome(outcomes[printed], outcomes[printed].line, settings);
        jobs_done();
      }
    };
    std::vector<std::thread> pool;
    const int n = std::min(workers, std::max(total, 1));
    for (int w = 0; w < n; ++w) pool.emplace_back(worker);
    for (std::thread& t : pool) t.join();
  }
  progress.clear();

  int bad = 0, internal = 0;
  for (const Outcome& o : outcomes)
    if (!o.ok) ++(o.failure.exit_code == kExitBadInput ? bad : internal);
  const int failed = bad + internal;
  if (failed > 0 || settings.verbose || (progress.enabled() && !settings.quiet))
    std::fprintf(stderr, "motionfield: %s\n",
                 printable("batch " + path + ": " + std::to_string(total) + " jobs, " + std::to_string(total - failed) +
                           " ok, " + std::to_string(failed) + " failed")
                     .c_str());
  if (internal > 0) return kExitInternal;
  if (bad > 0) return kExitBadInput;
  return kExitOk;
}

}  // namespace motionfield::cli
