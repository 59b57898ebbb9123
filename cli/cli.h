// What the parts of the motionfield CLI share: the global settings, printing
// a failure or warnings (the exit codes, Failure and the lines themselves are
// motionfield.hpp's, as the library's job runner makes them), and reading a
// file the CLI reads itself.
#pragma once

#include <string>
#include <vector>

#include "motionfield.hpp"

namespace motionfield::cli {

/// The global options (motionfield --help).
struct Settings {
  int threads = 1;                    ///< --threads: intra-op threads of each job (mf_set_num_threads: the BLAS's pool)
  bool verbose = false;
  bool quiet = false;                 ///< --quiet: no progress bar, no warnings
  bool json = false;                  ///< --json: a JSON summary of each job on stdout
  int jobs = 0;                       ///< batch --jobs: jobs run at once; 0: batch_workers() decides
  std::string model;                  ///< --model PATH, "" for the default model
  std::vector<std::string> twostage;  ///< --twostage PATH (repeatable)
  std::vector<std::string> citl;      ///< --citl PATH (repeatable)
  std::string rig_map;                ///< --rig-map FILE, "" for the automatic map
  std::string units;                  ///< --units, "" = auto
  std::string animation;              ///< --animation NAME|INDEX of glTF and FBX inputs, "" = the first

  /// The transformer files to add to the model, --twostage first.
  std::vector<std::string> transformers() const;
};

/// Prints failure_line(failure, prefix) (motionfield.hpp: "motionfield:
/// <prefix>error: ..." or "...internal error: ...", printable) on stderr.
void print_failure(const Failure& failure, const std::string& prefix = "");

/// Prints warning_lines(warnings, prefix) (motionfield.hpp: "motionfield:
/// <prefix>warning: <line>" per line, printable) on stderr.
void print_warnings(const std::string& warnings, const std::string& prefix = "");

/// The limit of a batch file or rig map file the CLI reads itself.
constexpr size_t kMaxCliTextFileBytes = size_t{64} << 20;

/// The text of a file the CLI reads itself (a batch file, a rig map): refuses
/// directories and devices (/dev/zero) and files over `max_bytes` before
/// reading them (pipes: while reading); InputError "cannot read the <what>
/// <path>: <reason>".
std::string read_text_file(const std::string& path, const std::string& what,
                           size_t max_bytes = kMaxCliTextFileBytes);

}  // namespace motionfield::cli
