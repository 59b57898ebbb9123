// Fuzz target: the JSON-lines batch job parser of the CLI (capi/cli/jsonl.h,
// used read-only) on any bytes: parse_json, then batch_job_from_json.
// Contract checked: bad JSON throws JsonError with a column inside the input
// (or one past it); a parsed value dumps to JSON that parses back to a value
// with the same dump (the sign of zero included: -0.0 dumps as "-0.0"); a job
// is read or refused with the CLI's InputError, nothing else.
#include <cstdint>
#include <string>

#include "capi/cli/jsonl.h"
#include "fuzz/fuzz_check.h"

using motionfield::cli::JsonError;
using motionfield::cli::JsonValue;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  JsonValue value;
  try {
    value = motionfield::cli::parse_json(text);
  } catch (const JsonError& e) {
    MF_FUZZ_CHECK(e.column() >= 1 && static_cast<size_t>(e.column()) <= size + 1);
    return 0;
  }
  const std::string dumped = value.dump();
  MF_FUZZ_CHECK(motionfield::cli::parse_json(dumped).dump() == dumped);
  try {
    const motionfield::cli::BatchJob job = motionfield::cli::batch_job_from_json(value);
    MF_FUZZ_CHECK(!job.task.empty() && !job.in.empty() && !job.out.empty());
  } catch (const motionfield::cli::InputError&) {
  }
  return 0;
}
