// One job (a batch line, or a single command of the CLI) end to end: read,
// solve, write; and its summary for --json.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "capi/src/jobs/jsonl.h"
#include "capi/src/jobs/models.h"
#include "motionfield.hpp"

namespace motionfield::jobs {

/// The options every job of a run shares (the CLI's global options).
struct JobSettings {
  int threads = 1;                        ///< intra-op threads, named in the --verbose line
  bool verbose = false;                   ///< a line of what ran and how long it took
  bool quiet = false;                     ///< no warnings
  std::string model;                      ///< --model PATH, "" for the default model
  std::vector<std::string> transformers;  ///< transformer files added to the model
  std::string rig_map;                    ///< --rig-map FILE, "" for the automatic map
  std::string units;                      ///< --units, "" = auto
};

/// A job's progress reports (mf_progress); return false to cancel.
using ProgressFn = std::function<bool(const mf_progress&)>;

/// What a job did, for --verbose and --json.
struct JobReport {
  std::string method;    ///< the method that ran (the default one resolved)
  std::string model;     ///< the model file, "" when none was used
  int frames_in = 0, frames_out = 0;
  double read_ms = 0, solve_ms = 0, write_ms = 0;
  std::string warnings;  ///< the task's warnings (Motion::warnings()) and the model's, one per line
  std::string verbose;   ///< with JobSettings::verbose, the line of what ran (no "motionfield: ", no newline)
  std::string constraints;  ///< the constraint report (mf_solution_get_report_json), "" when not asked for
  std::vector<std::string> alternatives;  ///< files the alternatives were written to
  int transition_frames = 0;  ///< a transition's generated frames (0: not a transition)
  int transition_first = 0;   ///< a transition's first generated frame in the whole clip
};

/// Where alternative `index` (1..) of output `out` goes: OUT_1.bvh for OUT.bvh.
std::string alternative_path(const std::string& out, int index);

/// The files of `job`, checked before anything is read (mf_output_set): its
/// inputs (input, path file, rig map, constraints and trajectory files) and
/// every output (the output, its alternatives OUT_1.bvh .., its report); no
/// two outputs, and no output and input, may be one file (by inode, through
/// links: ./a.bvh and a.bvh match). Also checks that the method exists and
/// re-navigation's numbers. Throws on the first problem.
OutputSet prepare_job(const BatchJob& job, const JobSettings& settings);

/// Runs `job`, whose files prepare_job gave, with the model `models` gives
/// for its method, reporting the solver's progress to `progress` (may be
/// empty). "-" as the input reads standard input, as the output writes
/// standard output. Its outputs are staged and put in place together at the
/// end, so a failed job leaves none of them. With `load_warnings` and the
/// default method, the model's load warnings (Models::load_warnings_of) lead
/// its warnings. With settings.verbose, the report says what ran and how long
/// each step took.
JobReport run_job(const BatchJob& job, OutputSet files, const JobSettings& settings, Models& models,
                  const ProgressFn& progress, bool load_warnings);

/// The --json summary of one job: {"task", "in", "out", "status": "ok" |
/// "error", "method", "model", "frames_in", "frames_out", "timings_ms":
/// {"read", "solve", "write", "total"}, "warnings": [...], and with
/// constraints "alternatives": [files] and "constraints": the report, for a
/// transition "transition": {"frames": N, "first_frame": I + 1}} when it ran, or
/// {"task", "in", "out", "status": "error", "exit_code", "error"} when it
/// failed; batch jobs add "line" and "id" (when given). One line of JSON.
std::string job_json(const BatchJob& job, const JobReport* report, const Failure* failure, size_t line = 0);

}  // namespace motionfield::jobs
