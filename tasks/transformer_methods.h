// The transformer in-betweeners (prior/inbetween/inbetweener.h) as task
// methods (tasks/method.h, transformer_methods(), registered by tasks/jobs.cc):
//   "context"  stage 0 of the two-stage model (Context Transformer)
//   "detail"   stage 1 of the two-stage model (Detail Transformer)
//   "citl"     the CITL model
// Each needs its model in TaskContext (twostage / citl); the C API loads them
// from motionfield-twostage.mfm and motionfield-citl.mfm next to the prior's
// model file (tasks/inbetweener_files.h). Each fills the motion with one pass
// of its model (inbetweener_fill() of tasks/inbetweener_fill.h,
// LongGapPolicy::Throw).
//
// This header also brings in those two headers for the callers that include
// it for them (the C API, the benchmarks).
#pragma once

#include "tasks/inbetweener_files.h"
#include "tasks/inbetweener_fill.h"
#include "tasks/method.h"
