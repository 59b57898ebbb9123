// motionfield.hpp must compile as C++17 with -pedantic -Wall -Wextra -Wshadow
// -Werror on its own (it includes what it uses).
#include "motionfield.hpp"

int use_motionfield_hpp() {
  const motionfield::Motion walk = motionfield::Motion::load_bvh("walk.bvh");
  return walk.frame_count() + static_cast<int>(motionfield::methods().size());
}
