// The motionfield command line on CLI11: the global options, the commands
// with their options and help texts, and where the parsed values go.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "cli.h"

namespace motionfield::cli {

/// The options of a task command (inbetween, fill, resample, renav, export)
/// that go into its job line as they are (commands.cc task_line).
struct JobOptions {
  std::string in, out;
  std::string method;            ///< "" = the default method
  int max_iterations = 0;        ///< 0: each method's own
  double fps = 0.0;              ///< resample: the target fps; renav: the output's (0 = the reference's)
  int frames = 0;                ///< renav --frames (0 = from the speed); transition --frames (0 = automatic)
  std::string constraints_file;  ///< inbetween, fill and transition: --constraints
  std::string trajectory_file;   ///< --trajectory
  int alternatives = 0;          ///< --alternatives
  std::string report_file;       ///< --report
  bool no_fallback = false;      ///< --no-fallback
};

/// Everything the command line sets. The task commands (inbetween, fill,
/// resample, renav) fill `job` directly, except the values that need parsing
/// or checking first (keyframes, gap, path).
struct Arguments {
  Settings settings;
  JobOptions job;
  std::string keyframes;  ///< inbetween --keyframes, as given
  std::string gap;        ///< fill --gap, as given
  std::string path;       ///< renav --path
  std::string polyline;   ///< renav --polyline
  std::string file;       ///< rig IN.bvh, batch JOBS.jsonl
  // transition A B (A is job.in; --frames is job.frames)
  std::string to;                ///< clip B
  int from_frame = -1;           ///< --from-frame
  int to_frame = 0;              ///< --to-frame
  std::string place = "auto";    ///< --place
  bool only_transition = false;  ///< --only-transition
  bool version = false;   ///< --version
};

/// Defines the command line on `app` (named "motionfield"), storing into `args`.
void define_command_line(CLI::App& app, Arguments& args);

}  // namespace motionfield::cli
