#include "training/augmentation.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>

#include "prior/motion/errors.h"
#include "prior/motion/interpolation.h"
#include "prior/motion/rotations.h"
#include "prior/rig/mirror.h"

namespace mf::training {
namespace {

// FNV-1a: a seed that is the same on every platform and run.
uint64_t name_hash(const std::string& name) {
  uint64_t h = 14695981039346656037ull;
  for (unsigned char c : name) h = (h ^ c) * 1099511628211ull;
  return h;
}

// Mean over frames of the lowest joint's height (Y up).
double mean_lowest_height(const Motion& motion) {
  const GlobalPose pose = forward_kinematics(motion);
  double sum = 0.0;
  for (int f = 0; f < pose.frames; ++f) {
    double low = std::numeric_limits<double>::infinity();
    for (int j = 0; j < pose.joints; ++j) low = std::min(low, pose.position(f, j).y());
    sum += low;
  }
  return pose.frames > 0 ? sum / pose.frames : 0.0;
}

void add_mirrors(Dataset& data, bool verbose) {
  data.train.reserve(2 * data.train.size());  // the pointers below stay valid while the mirrors are added
  std::vector<const Motion*> motions;
  for (const Clip& c : data.train) motions.push_back(&c.motion);
  const MirrorMap map = mirror_map(data.skeleton, mean_local_rotations(motions));
  const size_t n = data.train.size();
  for (size_t i = 0; i < n; ++i) data.train.push_back({data.train[i].name + "#mirror", mirror_motion(data.train[i].motion, map)});
  if (!verbose) return;
  // The twists are chosen to keep the mean local rotations; how close they stay says whether they were found.
  std::vector<const Motion*> mirrored;
  for (size_t i = n; i < data.train.size(); ++i) mirrored.push_back(&data.train[i].motion);
  const std::vector<Eigen::Quaterniond> a = mean_local_rotations(motions), b = mean_local_rotations(mirrored);
  double worst = 0.0;
  size_t at = 0;
  for (size_t j = 1; j < a.size(); ++j) {
    const double d = geodesic_angle(a[j], b[j]) * 180.0 / M_PI;
    if (d > worst) worst = d, at = j;
  }
  std::fprintf(stderr,
               "train: %zu mirrored clips added (rest offsets mirror within %.2f cm; mean local rotations "
               "within %.1f deg of the originals', the most at %s)\n",
               n, map.max_asymmetry * 100.0, worst, data.skeleton.names[at].c_str());
}

}  // namespace

void augment_training_split(Dataset& data, const Augmentation& a, bool verbose) {
  for (double s : a.speeds)
    if (!(s >= 0.5 && s <= 2.0) || std::abs(s - 1.0) < 1e-6)
      throw InputError("train: --speeds takes playback speeds in [0.5, 2] other than 1, got " + std::to_string(s));
  if (!(a.frame_noise_degrees >= 0.0 && a.frame_noise_degrees <= 45.0))
    throw InputError("train: --frame-noise takes degrees in [0, 45], got " + std::to_string(a.frame_noise_degrees));
  if (a.mirror) add_mirrors(data, verbose);
  if (a.frame_noise_degrees > 0.0) {
    const size_t n = data.train.size();
    data.train.reserve(2 * n);
    for (size_t i = 0; i < n; ++i)
      data.train.push_back({data.train[i].name + "#noise",
                            with_frame_noise(data.train[i].motion, a.frame_noise_degrees, name_hash(data.train[i].name))});
    if (verbose) std::fprintf(stderr, "train: %zu clips with joint frames turned by up to %g deg added\n", n, a.frame_noise_degrees);
  }
  if (!a.speeds.empty()) {
    const size_t n = data.train.size();
    data.train.reserve(n * (1 + a.speeds.size()));
    for (double s : a.speeds)
      for (size_t i = 0; i < n; ++i) {
        char name[32];
        std::snprintf(name, sizeof name, "@%gx", s);
        data.train.push_back({data.train[i].name + name, played_at_speed(data.train[i].motion, s)});
      }
    if (verbose) std::fprintf(stderr, "train: %zu clips played at other speeds added\n", n * a.speeds.size());
  }
}


Motion with_frame_noise(const Motion& motion, double max_degrees, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const int J = motion.num_joints();
  std::vector<Eigen::Quaterniond> change(J, Eigen::Quaterniond::Identity());
  for (int j = 1; j < J; ++j) {
    Eigen::Vector3d axis(normal(rng), normal(rng), normal(rng));
    if (axis.norm() < 1e-9) axis = Eigen::Vector3d::UnitY();
    change[j] = Eigen::AngleAxisd(uniform(rng) * max_degrees * M_PI / 180.0, axis.normalized());
  }
  Motion noisy = motion;
  for (int f = 0; f < motion.num_frames(); ++f)
    for (int j = 1; j < J; ++j) {
      const int p = motion.skeleton.parents[j];
      noisy.rotation(f, j) = change[p].conjugate() * motion.rotation(f, j).normalized() * change[j];
    }
  const double lift = mean_lowest_height(motion) - mean_lowest_height(noisy);
  for (Eigen::Vector3d& p : noisy.root_positions) p.y() += lift;
  return noisy;
}

}  // namespace mf::training
