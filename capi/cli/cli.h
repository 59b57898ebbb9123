// What the parts of the motionfield CLI share: the exit codes, the global
// settings, and how a failure becomes a message and an exit code.
#pragma once

#include <string>
#include <vector>

namespace motionfield::cli {

constexpr int kExitOk = 0;
constexpr int kExitInternal = 1;
constexpr int kExitBadInput = 2;

/// The global options (motionfield --help).
struct Settings {
  int threads = 1;                    ///< --threads: intra-op threads of each job (TaskThreads in capi/src/capi_internal.h: why 1)
  bool verbose = false;
  bool quiet = false;                 ///< --quiet: no progress bar, no warnings
  bool json = false;                  ///< --json: a JSON summary of each job on stdout
  int jobs = 0;                       ///< batch --jobs: jobs run at once; 0: batch_workers() decides
  std::string model;                  ///< --model PATH, "" for the default model
  std::vector<std::string> twostage;  ///< --twostage PATH (repeatable)
  std::vector<std::string> citl;      ///< --citl PATH (repeatable)
  std::string rig_map;                ///< --rig-map FILE, "" for the automatic map
  std::string units;                  ///< --units, "" = auto

  /// The transformer files to add to the model, --twostage first.
  std::vector<std::string> transformers() const;
};

/// A failure as the user sees it: exit code 2 for bad input (InputError, and
/// the C API's invalid-argument, I/O, model and unsupported statuses), else 1
/// (internal); the message (for internal errors with the status name).
struct Failure {
  int exit_code = kExitInternal;
  std::string message;
};

/// The Failure of the exception being handled; call only inside a catch block.
Failure current_failure();

/// `text` safe to print (the library's mf_printable_text: control bytes and
/// escape sequences escaped, at most MF_MESSAGE_MAX_BYTES): everything the CLI
/// prints that holds a file name or bytes of the input goes through it.
std::string printable(const std::string& text);

/// Prints "motionfield: <prefix>error: ..." or "...internal error: ..." on
/// stderr (printable).
void print_failure(const Failure& failure, const std::string& prefix = "");

/// Prints each line of `warnings` as "motionfield: <prefix>warning: <line>" on
/// stderr (printable).
void print_warnings(const std::string& warnings, const std::string& prefix = "");

/// The limit of a batch file or rig map file the CLI reads itself.
constexpr size_t kMaxCliTextFileBytes = size_t{64} << 20;

/// The text of a file the CLI reads itself (a batch file, a rig map): refuses
/// directories and devices (/dev/zero) and files over `max_bytes` before
/// reading them (pipes: while reading); InputError "cannot read the <what>
/// <path>: <reason>".
std::string read_text_file(const std::string& path, const std::string& what,
                           size_t max_bytes = kMaxCliTextFileBytes);

/// Metres per file unit of --units / a batch job's "units": "" or "auto" = 0
/// (detected), a unit name (mf_length_unit_scale) or a positive number.
/// `what` names the option in messages.
double units_scale(const std::string& units, const std::string& what);

}  // namespace motionfield::cli
