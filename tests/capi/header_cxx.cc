// motionfield.h must compile as C++ with -pedantic -Wall -Wextra -Werror, and
// its declarations must have C linkage.
#include "motionfield.h"

#include <type_traits>

static_assert(std::is_same<decltype(&mf_abi_version), uint32_t (*)()>::value, "mf_abi_version");
static_assert(std::is_standard_layout<mf_task_options>::value, "plain C struct");

int use_motionfield() {
  mf_task_options options;
  mf_task_options_init(&options);
  options.progress = [](void*, const mf_progress* p) -> int { return p->iteration > 100; };
  mf_motion* m = nullptr;
  const int status = mf_motion_load_bvh("walk.bvh", nullptr, &m);
  mf_motion_destroy(m);
  return status;
}
