// Fuzz target: the JSON-lines batch job parser of the library (capi/src/jobs/jsonl.h,
// used read-only) on any bytes: parse_json, then batch_job_from_json.
// Contract checked: bad JSON throws JsonError with a column inside the input
// (or one past it); a parsed value dumps to JSON that parses back to a value
// with the same dump (the sign of zero included: -0.0 dumps as "-0.0"); a job
// is read or refused with the jobs' InputError, nothing else.
#include <cstdint>
#include <string>

#include "capi/src/jobs/jsonl.h"
#include "fuzz/fuzz_check.h"

using motionfield::jobs::JsonError;
using motionfield::jobs::JsonValue;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  JsonValue value;
  try {
    value = motionfield::jobs::parse_json(text);
  } catch (const JsonError& e) {
    MF_FUZZ_CHECK(e.column() >= 1 && static_cast<size_t>(e.column()) <= size + 1);
    return 0;
  }
  const std::string dumped = value.dump();
  MF_FUZZ_CHECK(motionfield::jobs::parse_json(dumped).dump() == dumped);
  try {
    const motionfield::jobs::BatchJob job = motionfield::jobs::batch_job_from_json(value);
    MF_FUZZ_CHECK(!job.task.empty() && !job.in.empty() && !job.out.empty());
  } catch (const motionfield::InputError&) {
  }
  return 0;
}
