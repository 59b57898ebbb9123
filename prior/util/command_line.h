// The shared frame of motionfield's command-line tools (the trainer, the
// benchmark programs, mf_inspect_dataset): CLI11 (header-only, Debian's
// libcli11-dev) parses the arguments, and every tool ends the same way:
//   0  success, and for --help (the help on stdout)
//   2  bad input: an unknown, missing or malformed option, or an mf::InputError
//      from the tool itself; "<tool>: <message>" on stderr
//   1  any other error; "<tool>: internal error: <message>" on stderr
// Only executables include this header (the libraries never parse arguments).
#pragma once

#include <CLI/CLI.hpp>
#include <malloc.h>

#include <cstdio>
#include <exception>
#include <limits>
#include <string>

#include "prior/motion/errors.h"

namespace mf::cli {

/// The conventions of every tool: a repeated option keeps its last value (as
/// the hand-written parsers did), and --help shows each option's default.
inline void use_tool_defaults(CLI::App& app) {
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast)->always_capture_default();
  app.get_formatter()->column_width(28);
}

/// A check for integer options: at least `min` (CLI11's PositiveNumber prints
/// the double range in full).
inline CLI::Range at_least(int min) { return CLI::Range(min, std::numeric_limits<int>::max()); }

/// An option that may be given several times, one value each time, and keeps
/// every value ("--hp a=1 --hp b=2").
inline CLI::Option* repeatable(CLI::Option* option) {
  return option->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)->allow_extra_args(false);
}

/// Lets glibc's heap keep 64 MB above its top when it grows and when it trims.
/// Without it, malloc hands the freed top of the heap back to the system
/// between the solver's iterations and takes it back, paying a page fault for
/// each page touched again: 232k against 156k minor faults, and up to 30 %
/// longer sparse solves, in whichever process lands in that state
/// (docs/BENCHMARKS.md, "The heap setting"). The CLI sets the same (cli/main.cc);
/// the library leaves its host's allocator alone.
inline void pad_heap_top() { mallopt(M_TOP_PAD, 64 << 20); }

/// Pads the heap (pad_heap_top), parses argc/argv into `app`, then returns
/// `body()`, mapping every outcome to the exit codes above. `body` may throw
/// mf::InputError (exit code 2) or any other std::exception (exit code 1).
template <class Body>
int run(CLI::App& app, int argc, char** argv, Body&& body) {
  const std::string tool = app.get_name();
  pad_heap_top();
  try {
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);  // --help
      std::fprintf(stderr, "%s: %s\n(%s --help lists the options)\n", tool.c_str(), e.what(), tool.c_str());
      return 2;
    }
    return body();
  } catch (const InputError& e) {
    std::fprintf(stderr, "%s: %s\n", tool.c_str(), e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: internal error: %s\n", tool.c_str(), e.what());
    return 1;
  }
}

}  // namespace mf::cli
