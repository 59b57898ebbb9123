// The commands of the motionfield CLI, run once the command line is parsed.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "app.h"
#include "cli.h"

namespace motionfield::cli {

/// Runs the command `app` (set up by define_command_line) parsed into `args`;
/// returns the exit code. Throws InputError and motionfield::Error.
int run_command(const CLI::App& app, const Arguments& args);

/// `motionfield batch JOBS.jsonl` (batch.cc).
int command_batch(const std::string& path, const Settings& settings);

}  // namespace motionfield::cli
