#include "tasks/method.h"

namespace mf {

std::vector<Method> prior_methods() { return {}; }

}  // namespace mf
