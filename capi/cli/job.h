// One job of the CLI, from the command line or a batch line, end to end:
// read, solve, write; and its summary for --json.
#pragma once

#include <string>
#include <vector>

#include "cli.h"
#include "jsonl.h"
#include "models.h"
#include "progress.h"

namespace motionfield::cli {

/// What a job did, for --verbose and --json.
struct JobReport {
  std::string method;    ///< the method that ran (the default one resolved)
  std::string model;     ///< the model file, "" when none was used
  int frames_in = 0, frames_out = 0;
  double read_ms = 0, solve_ms = 0, write_ms = 0;
  std::string warnings;  ///< the task's warnings (Motion::warnings()) and the CLI's, one per line
  std::string constraints;  ///< the constraint report (mf_solution_get_report_json), "" when not asked for
  std::vector<std::string> alternatives;  ///< files the alternatives were written to
};

/// Where alternative `index` (1..) of output `out` goes: OUT_1.bvh for OUT.bvh.
std::string alternative_path(const std::string& out, int index);

/// The files of `job`, checked before anything is read (mf_output_set): its
/// inputs (input, path file, rig map, constraints and trajectory files) and
/// every output (the output, its alternatives OUT_1.bvh .., its report); no
/// two outputs, and no output and input, may be one file (by inode, through
/// links: ./a.bvh and a.bvh match). Also checks that the method exists and
/// re-navigation's numbers. Throws on the first problem.
OutputSet prepare_job(const BatchJob& job, const Settings& settings);

/// Runs `job` with the model `models` gives for its method, showing the
/// solver's progress on `progress`. "-" as the input reads standard input, as
/// the output writes standard output. Its files are checked first
/// (prepare_job); its outputs are staged and put in place together at the
/// end, so a failed job leaves none of them. With settings.verbose, prints
/// what ran and how long each step took (stderr).
JobReport run_job(const BatchJob& job, const Settings& settings, Models& models, ProgressLine& progress);
/// The same with the files prepare_job gave (a batch checks them all first).
JobReport run_job(const BatchJob& job, OutputSet files, const Settings& settings, Models& models,
                  ProgressLine& progress);

/// The --json summary of one job: {"task", "in", "out", "status": "ok" |
/// "error", "method", "model", "frames_in", "frames_out", "timings_ms":
/// {"read", "solve", "write", "total"}, "warnings": [...], and with
/// constraints "alternatives": [files] and "constraints": the report} when it ran, or
/// {"task", "in", "out", "status": "error", "exit_code", "error"} when it
/// failed; batch jobs add "line" and "id" (when given). One line of JSON.
std::string job_json(const BatchJob& job, const JobReport* report, const Failure* failure, size_t line = 0);

}  // namespace motionfield::cli
