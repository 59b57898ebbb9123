// A run of jobs (a batch file's lines, or a single command): the settings
// they share, the model they load once, the files the lines checked so far
// read and write, and each job's outcome as the CLI reports it (its stderr
// lines and its --json summary). Behind mf_job_runner (motionfield.h).
#pragma once

#include <cstddef>
#include <mutex>
#include <string>
#include <vector>

#include "capi/src/jobs/job.h"

namespace motionfield::jobs {

/// What a finished job says.
struct JobResult {
  int exit_code = kExitOk;  ///< 0 ok, 2 bad input, 1 internal error
  std::string messages;     ///< its stderr lines, each "motionfield: ...\n"
  std::string json;         ///< its --json summary (one line, no newline)
};

/// One line, parsed and its files checked: runnable, or its failure.
struct CheckedJob {
  size_t line = 0;             ///< 1-based; 0 for a single command
  std::string label;           ///< "<batch> line N (id X)" in messages; "" for a single command
  BatchJob job;
  OutputSet files;             ///< the job's files (prepare_job)
  bool runnable = false;
  Failure failure;             ///< why it is not runnable
  bool load_warnings = false;  ///< the model's load warnings go with this job's
};

/// The end of a batch (mf_job_batch_summary). `flags`: MF_JOB_VERBOSE,
/// MF_JOB_QUIET, MF_JOB_PROGRESS_SHOWN.
BatchSummary batch_summary(const std::string& batch_path, const std::vector<int>& exit_codes, uint32_t flags);

class JobRunner {
 public:
  /// Loads settings.model, if given (throws as Models::load_explicit).
  /// `preload`: check_line loads the model each job needs (jobs then run side
  /// by side without loading it).
  JobRunner(JobSettings settings, bool preload);

  /// Parses line `line` (1-based) of the batch file `batch_path` and checks its
  /// files against every line checked before (so that which of two jobs
  /// writing one file is refused does not depend on timing). The first
  /// runnable job naming no method gets the model's load warnings.
  CheckedJob check_line(const std::string& text, size_t line, const std::string& batch_path);

  /// Runs a checked job (a job that is not runnable gives its failure).
  JobResult run(CheckedJob job, const ProgressFn& progress);

  /// Parses, checks (against nothing else) and runs one line. `single`: a
  /// command of the CLI ("-" allowed, task "export", messages without a
  /// label, no "line" in the summary). `load_warnings`: as CheckedJob's.
  JobResult run_line(const std::string& text, size_t line, const std::string& batch_path, bool single,
                     bool load_warnings, const ProgressFn& progress);

  /// Loads the model (the explicit one, else the default one) if not yet;
  /// returns it (an empty Model when there is none).
  const Model& load_model();

  /// The loaded model's path ("" before one is loaded).
  std::string model_path() const { return models_.path(); }

 private:
  void parse(const std::string& text, bool single, CheckedJob* job) const;
  JobResult outcome(const CheckedJob& job, const JobReport* report, const Failure* failure) const;

  JobSettings settings_;
  bool preload_;
  Models models_;
  OutputSet batch_files_;
  bool load_warnings_given_ = false;
  std::mutex mutex_;  // check_line
};

}  // namespace motionfield::jobs
