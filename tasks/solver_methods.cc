#include "tasks/method.h"

namespace mf {

std::vector<Method> solver_methods() { return {}; }

}  // namespace mf
