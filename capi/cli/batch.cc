// `motionfield batch JOBS.jsonl`: one job per line, each failure reported
// with its line, the others still run.
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <system_error>
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

// The outputs of the batch's jobs so far: a job may not write what an earlier
// line writes (the later result would silently replace the earlier one).
class Outputs {
 public:
  // Claims `out` for `line`; InputError naming the earlier line if it is taken.
  void claim(const std::string& out, size_t line) {
    namespace fs = std::filesystem;
    std::error_code ec;
    // Devices and FIFOs (/dev/null) may be written by every job.
    if (fs::exists(out, ec) && !fs::is_regular_file(out, ec)) return;
    fs::path key = fs::weakly_canonical(fs::absolute(out, ec), ec);
    if (ec) key = fs::absolute(out).lexically_normal();
    const auto [it, added] = lines_.emplace(key.string(), line);
    if (!added)
      throw InputError("line " + std::to_string(it->second) + " already writes " + out +
                       ": refusing to overwrite another job's output (give each job its own \"out\")");
  }

 private:
  std::map<std::string, size_t> lines_;
};

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

}  // namespace

int command_batch(const std::string& path, const Settings& settings) {
  const std::vector<std::string> lines = read_lines(path);
  Models models(settings.model, settings.transformers());
  models.load_explicit();
  int total = 0;
  for (const std::string& l : lines) total += blank(l) ? 0 : 1;
  ProgressLine progress(ProgressLine::stderr_is_terminal() && !settings.quiet);
  Outputs outputs;
  int done = 0, bad = 0, internal = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (blank(lines[i])) continue;
    std::string label = path + " line " + std::to_string(i + 1);
    progress.start("[" + std::to_string(done + 1) + "/" + std::to_string(total) + "] line " + std::to_string(i + 1));
    BatchJob job;
    try {
      job = parse_line(lines[i], &label);
      outputs.claim(job.out, i + 1);
      const JobReport report = run_job(job, settings, models, progress);
      progress.clear();
      if (!settings.quiet) print_warnings(report.warnings, label + ": ");
      if (settings.json) std::printf("%s\n", job_json(job, &report, nullptr, i + 1).c_str());
    } catch (...) {
      const Failure failure = current_failure();
      ++(failure.exit_code == kExitBadInput ? bad : internal);
      progress.clear();
      print_failure(failure, label + ": ");
      if (settings.json) {
        Failure shown = failure;
        shown.message = printable(failure.message);
        std::printf("%s\n", job_json(job, nullptr, &shown, i + 1).c_str());
      }
    }
    if (settings.json) std::fflush(stdout);
    ++done;
  }
  progress.clear();
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
