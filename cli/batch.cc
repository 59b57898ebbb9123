// `motionfield batch JOBS.jsonl [--jobs N]`: one job per line, each failure
// reported with its line, the others still run; N jobs at once on one model.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "commands.h"
#include "motionfield.hpp"
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

// One line's job, checked by the library, then what its run said.
struct Outcome {
  size_t line = 0;  ///< 1-based
  Job job;
  JobResult result;
};

// Prints what a finished line says (its stderr lines; its --json line).
void print_outcome(const Outcome& o, const Settings& settings) {
  std::fputs(o.result.messages.c_str(), stderr);
  if (settings.json) {
    std::printf("%s\n", o.result.json.c_str());
    std::fflush(stdout);
  }
}

// --jobs, else one job per core's worth of --threads: jobs side by side use
// the cores better than threads inside one job (docs/BENCHMARKS.md, "Threads":
// a 128-frame solve is only 3-20 % faster on two threads of an idle machine,
// and far slower when the cores are busy).
// At most 8 by default: every job holds its own solver's buffers.
int batch_workers(const Settings& settings) {
  if (settings.jobs > 0) return settings.jobs;
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return std::clamp(cores / std::max(1, settings.threads), 1, 8);
}

// Every line parsed and its files checked first, in line order, against its
// own and every earlier line's (the runner keeps them); with --jobs N, the
// model a job needs is loaded here too, once, before any worker runs.
std::vector<Outcome> check_lines(const std::vector<std::string>& lines, const std::string& path, JobRunner& runner) {
  std::vector<Outcome> outcomes;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (blank(lines[i])) continue;
    Outcome o;
    o.line = i + 1;
    o.job = runner.check_line(lines[i], o.line, path);
    outcomes.push_back(std::move(o));
  }
  return outcomes;
}

// Prints the batch's last line (on failures, with --verbose, or after a
// progress line) and returns its exit code (mf_job_batch_summary).
int summary(const std::string& path, const std::vector<Outcome>& outcomes, const Settings& settings,
            bool progress_shown) {
  std::vector<int32_t> codes;
  for (const Outcome& o : outcomes) codes.push_back(o.result.exit_code);
  const uint32_t flags = (settings.verbose ? MF_JOB_VERBOSE : 0u) | (settings.quiet ? MF_JOB_QUIET : 0u) |
                         (progress_shown ? MF_JOB_PROGRESS_SHOWN : 0u);
  const BatchSummary s = batch_summary(path, codes, flags);
  std::fputs(s.line.c_str(), stderr);
  return s.exit_code;
}

}  // namespace

int command_batch(const std::string& path, const Settings& settings) {
  const std::vector<std::string> lines = read_lines(path);
  const int workers = batch_workers(settings);
  JobRunner runner = make_runner(settings, workers > 1 ? MF_JOB_PRELOAD_MODEL : 0u);
  if (settings.verbose) std::fprintf(stderr, "motionfield: batch: %d job%s at once\n", workers, workers == 1 ? "" : "s");

  std::vector<Outcome> outcomes = check_lines(lines, path, runner);
  const int total = static_cast<int>(outcomes.size());

  ProgressLine progress(ProgressLine::stderr_is_terminal() && !settings.quiet);
  const auto run = [&](size_t k, ProgressLine& line) {
    std::function<bool(const mf_progress&)> report;
    if (line.enabled()) report = [&line](const mf_progress& p) { return line.update(p); };
    outcomes[k].result = runner.run(outcomes[k].job, report);
    line.clear();
  };
  if (workers <= 1) {
    for (size_t k = 0; k < outcomes.size(); ++k) {
      progress.start("[" + std::to_string(k + 1) + "/" + std::to_string(total) + "] line " + std::to_string(outcomes[k].line));
      run(k, progress);
      print_outcome(outcomes[k], settings);
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
          print_outcome(outcomes[printed], settings);
        jobs_done();
      }
    };
    std::vector<std::thread> pool;
    const int n = std::min(workers, std::max(total, 1));
    for (int w = 0; w < n; ++w) pool.emplace_back(worker);
    for (std::thread& t : pool) t.join();
  }
  progress.clear();

  return summary(path, outcomes, settings, progress.enabled());
}

}  // namespace motionfield::cli
