// One job of the CLI, from the command line or a batch line, end to end:
// read, solve, write.
#pragma once

#include <string>

#include "cli.h"
#include "jsonl.h"
#include "models.h"

namespace motionfield::cli {

/// Runs `job` with the model `models` gives for its method. Returns the
/// warnings of the task (Motion::warnings(), one per line; "" if none). With
/// settings.verbose, prints what ran and how long each step took (stderr).
std::string run_job(const BatchJob& job, const Settings& settings, Models& models);

}  // namespace motionfield::cli
