// `motionfield batch JOBS.jsonl`: one job per line, each failure reported
// with its line, the others still run.
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "commands.h"
#include "input_error.h"
#include "job.h"
#include "jsonl.h"
#include "models.h"

namespace motionfield::cli {
namespace {

bool blank(const std::string& line) { return line.find_first_not_of(" \t\r\n") == std::string::npos; }

std::vector<std::string> read_lines(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError("cannot open " + path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(file, line);) lines.push_back(line);
  if (file.bad()) throw InputError("cannot read " + path);
  if (!lines.empty() && lines[0].compare(0, 3, "\xEF\xBB\xBF") == 0) lines[0].erase(0, 3);  // UTF-8 BOM
  return lines;
}

// The progress line on stderr, when it is a terminal.
class Progress {
 public:
  explicit Progress(int total) : total_(total), shown_(isatty(STDERR_FILENO) == 1) {}
  bool shown() const { return shown_; }
  void show(int done, size_t line) const {
    if (!shown_) return;
    std::fprintf(stderr, "\r\033[K[%d/%d] line %zu", done + 1, total_, line);
    std::fflush(stderr);
  }
  void clear() const {
    if (shown_) std::fputs("\r\033[K", stderr);
  }

 private:
  int total_;
  bool shown_;
};

// Runs the job of one line; `label` gains the job's id once the line parses.
std::string run_line(const std::string& line, std::string* label, const Settings& settings, Models& models) {
  JsonValue value;
  try {
    value = parse_json(line);
  } catch (const JsonError& e) {
    throw InputError(std::string("invalid JSON: ") + e.what());
  }
  if (const JsonValue* id = value.find("id"))
    *label += " (id " + (id->is_string() ? id->as_string() : id->dump()) + ")";
  return run_job(batch_job_from_json(value), settings, models);
}

}  // namespace

int command_batch(const std::string& path, const Settings& settings) {
  const std::vector<std::string> lines = read_lines(path);
  Models models(settings.model, settings.transformers());
  models.load_explicit();
  int total = 0;
  for (const std::string& l : lines) total += blank(l) ? 0 : 1;
  const Progress progress(total);
  int done = 0, bad = 0, internal = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (blank(lines[i])) continue;
    std::string label = path + " line " + std::to_string(i + 1);
    progress.show(done, i + 1);
    try {
      const std::string warnings = run_line(lines[i], &label, settings, models);
      progress.clear();
      print_warnings(warnings, label + ": ");
    } catch (...) {
      const Failure failure = current_failure();
      ++(failure.exit_code == kExitBadInput ? bad : internal);
      progress.clear();
      print_failure(failure, label + ": ");
    }
    ++done;
  }
  progress.clear();
  const int failed = bad + internal;
  if (failed > 0 || settings.verbose || progress.shown())
    std::fprintf(stderr, "motionfield: batch %s: %d jobs, %d ok, %d failed\n", path.c_str(), total, total - failed,
                 failed);
  if (internal > 0) return kExitInternal;
  if (bad > 0) return kExitBadInput;
  return kExitOk;
}

}  // namespace motionfield::cli
