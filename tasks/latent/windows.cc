#include "tasks/latent/windows.h"

#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"

namespace mf {

std::vector<int> window_starts(int frames, int window, int hop) {
  if (frames < 1 || window < 2 || hop < 1 || hop >= window) {
    throw InputError("window_starts: need frames >= 1, window >= 2 and 1 <= hop < window");
  }
  std::vector<int> starts{0};
  if (frames <= window) return starts;
  for (int s = hop; s + window < frames; s += hop) starts.push_back(s);
  starts.push_back(frames - window);
  return starts;
}

void cross_fade_frame(const Motion& piece, int f, double w, Motion* out, int g) {
  for (int j = 0; j < piece.num_joints(); ++j) {
    out->rotation(g, j) = w >= 1.0 ? piece.rotation(f, j) : slerp(out->rotation(g, j), piece.rotation(f, j), w);
  }
  out->root_positions[g] = w >= 1.0 ? piece.root_positions[f]
                                    : Eigen::Vector3d(out->root_positions[g] * (1.0 - w) + piece.root_positions[f] * w);
}

}  // namespace mf
