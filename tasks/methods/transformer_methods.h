// The transformer in-betweeners (prior/runtime/inbetween_runtime.h) as task
// methods (tasks/methods/method.h, transformer_methods(), registered by tasks/methods/jobs.cc):
//   "context"  stage 0 of the two-stage model (Context Transformer)
//   "detail"   stage 1 of the two-stage model (Detail Transformer)
//   "citl"     the CITL model
//   "keyframe" stage 0 of KeyframeNet + RefineNet (the interpolated keyframes)
//   "refine"   stage 1 of KeyframeNet + RefineNet (trajectory-conditioned)
// (one method per stage of every kind of inbetweener_kinds()). Each needs its
// model in TaskContext (twostage / citl / keyframe); the C API loads them from
// motionfield-<kind>.mfm next to the prior's model file
// (tasks/transformer/inbetweener_files.h). Each fills the motion with one pass of its model
// (inbetweener_fill() of tasks/transformer/inbetweener_fill.h, LongGapPolicy::Throw), from
// whole-pose keys (Method::complete) or from keys and a trajectory
// (Method::complete_constrained, one answer; effector targets and contact pins
// are refused with mf::InputError).
//
// This header also brings in those two headers for the callers that include
// it for them (the C API, the benchmarks).
#pragma once

#include "tasks/methods/method.h"
#include "tasks/transformer/inbetweener_files.h"
#include "tasks/transformer/inbetweener_fill.h"
