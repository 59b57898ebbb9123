// The commands of the motionfield CLI, run once the command line is parsed.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "app.h"
#include "cli.h"
#include "motionfield.hpp"

namespace motionfield::cli {

/// Runs the command `app` (set up by define_command_line) parsed into `args`;
/// returns the exit code. Throws InputError and motionfield::Error.
int run_command(const CLI::App& app, const Arguments& args);

/// The library's job runner with the command line's settings and `flags`
/// (MF_JOB_PRELOAD_MODEL); loads --model.
JobRunner make_runner(const Settings& settings, uint32_t flags = 0);

/// `motionfield batch JOBS.jsonl` (batch.cc).
int command_batch(const std::string& path, const Settings& settings);

}  // namespace motionfield::cli
