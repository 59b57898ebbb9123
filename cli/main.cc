// motionfield: the command-line front end (in-betweening, gap filling,
// resampling, re-navigation, batch runs, rig descriptions). A client of the C
// API through motionfield.hpp, like any other program: it includes nothing of
// the library's internals (the build gives it no path to them).
//   app.cc       the command line (CLI11): options and help texts
//   commands.cc  the commands; batch.cc the batch command; progress.cc the
//                progress bar
// Every job (a batch line, a task command) is parsed, checked and run by the
// library's job runner (mf_job_runner, capi/src/jobs/).
// Exit codes: 0 ok, 2 bad input, 1 internal error; every message goes to
// stderr, prefixed with "motionfield: ", with control characters escaped
// (cli.h printable).
#include <CLI/CLI.hpp>
#include <malloc.h>

#include <cstdio>
#include <string>

#include "app.h"
#include "cli.h"
#include "commands.h"

namespace {

using namespace motionfield;
using namespace motionfield::cli;

// A parse error as "motionfield: error: ..." with the command's help to see.
int report_parse_error(const CLI::App& app, const CLI::ParseError& e) {
  const std::vector<CLI::App*> chosen = app.get_subcommands();
  const std::string help =
      chosen.empty() ? "motionfield --help" : "motionfield " + chosen.front()->get_name() + " --help";
  std::string message = e.what();
  if (dynamic_cast<const CLI::ExtrasError*>(&e)) {
    // CLI11 lists the extras in reverse; name them in order, and an unknown command as such.
    const std::vector<std::string> extras = app.remaining(true);
    message.clear();
    for (const std::string& arg : extras) message += (message.empty() ? "" : " ") + arg;
    const bool command = chosen.empty() && !extras.empty() && extras.front().rfind("-", 0) != 0;
    message = command ? "unknown command '" + extras.front() + "'" : "unexpected arguments: " + message;
  }
  print_failure({kExitBadInput, message + " (see " + help + ")"});
  return kExitBadInput;
}

}  // namespace

int main(int argc, char** argv) {
  // glibc's heap keeps 64 MB above its top, so that the solvers' iterations do
  // not hand memory back to the system and fault it in again (the tools do the
  // same: prior/util/command_line.h, pad_heap_top).
  mallopt(M_TOP_PAD, 64 << 20);
  CLI::App app("", "motionfield");
  Arguments args;
  try {
    define_command_line(app, args);
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);  // --help, --version
      return report_parse_error(app, e);
    }
    return run_command(app, args);
  } catch (...) {
    const Failure failure = current_failure();
    print_failure(failure);
    return failure.exit_code;
  }
}
