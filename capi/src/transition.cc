// mf_transition: two clips in, one transition out (tasks/transition/transition.h),
// its result an mf_solution.
#include <memory>
#include <string>

#include "capi/src/capi_internal.h"
#include "tasks/transition/transition.h"

namespace mf::capi {
namespace {

// The transition request of the C options (NULL: the defaults of _init).
TransitionRequest transition_request(const mf_transition_options* user) {
  mf_transition_options o;
  mf_transition_options_init(&o);
  if (user) o = read_options(user, "mf_transition_options");
  if (o.place != MF_PLACE_AUTO && o.place != MF_PLACE_KEEP)
    throw ApiError(MF_ERROR_INVALID_ARGUMENT, "mf_transition_options.place is " + std::to_string(o.place) +
                                                  ": must be MF_PLACE_AUTO (0) or MF_PLACE_KEEP (1)");
  TransitionRequest r;
  r.frames = o.frames;
  r.from_frame = o.from_frame;
  r.to_frame = o.to_frame;
  r.place = o.place == MF_PLACE_KEEP ? TransitionRequest::Placement::kKeep : TransitionRequest::Placement::kAuto;
  r.only_transition = o.only_transition != 0;
  return r;
}

}  // namespace
}  // namespace mf::capi

using mf::capi::guard;
using mf::capi::require;

extern "C" {

int mf_transition_options_init(mf_transition_options* options) {
  return guard([&] {
    require(options, "options");
    std::memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
    options->from_frame = -1;
    options->place = MF_PLACE_AUTO;
  });
}

int mf_transition(const mf_model* model, const mf_motion* a, const mf_motion* b,
                  const mf_transition_options* transition, const mf_constraints* constraints, int32_t alternatives,
                  const mf_task_options* options, mf_solution** out) {
  return guard([&] {
    require(a, "a");
    require(b, "b");
    require(out, "out");
    mf::TransitionRequest request = mf::capi::transition_request(transition);
    if (constraints) request.constraints = constraints->spec;
    request.length_scale = a->length_scale;
    const mf_task_options o = mf::capi::read_options(options, "mf_task_options");
    const mf::TaskContext ctx = mf::capi::task_context(model, o);
    const mf::capi::TaskThreads threads;
    mf::TransitionResult r =
        mf::run_transition(a->motion, b->motion, request, o.method ? std::string(o.method) : std::string(),
                           alternatives, ctx);
    const bool trajectory = !request.constraints.trajectory.empty();
    std::unique_ptr<mf_solution> s = mf::capi::new_solution(std::move(r), *a, trajectory);
    s->transition_frames = r.frames;
    s->transition_first = r.first_frame;
    *out = s.release();
  });
}

int mf_solution_get_transition(const mf_solution* solution, int32_t* frames, int32_t* first_frame) {
  return guard([&] {
    require(solution, "solution");
    if (solution->transition_frames == 0)
      throw mf::capi::ApiError(MF_ERROR_INVALID_ARGUMENT, "the solution is not a transition's (mf_transition)");
    if (frames) *frames = solution->transition_frames;
    if (first_frame) *first_frame = solution->transition_first;
  });
}

}  // extern "C"
