// The motionfield command line on CLI11: the global options, the commands
// with their options and help texts, and where the parsed values go.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "cli.h"
#include "jsonl.h"

namespace motionfield::cli {

/// Everything the command line sets. The task commands (inbetween, fill,
/// resample, renav) fill `job` directly, except the values that need parsing
/// or checking first (keyframes, gap, path).
struct Arguments {
  Settings settings;
  BatchJob job;
  std::string keyframes;  ///< inbetween --keyframes, as given
  std::string gap;        ///< fill --gap, as given
  std::string path;       ///< renav --path
  std::string polyline;   ///< renav --polyline
  std::string file;       ///< rig IN.bvh, batch JOBS.jsonl
  bool version = false;   ///< --version
};

/// Defines the command line on `app` (named "motionfield"), storing into `args`.
void define_command_line(CLI::App& app, Arguments& args);

}  // namespace motionfield::cli
