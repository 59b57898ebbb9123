// mf_bvh_diff: compares two BVH files through the C API, for tests
// (tests/cli_test.sh); it replaces the hidden `motionfield diff` of the CLI,
// which shipped a test aid to users.
//
//   mf_bvh_diff A.bvh B.bvh [--tol T] [--frames LIST] [--step K] [--units U]
//
// Compares frame f of A with frame f*K of B (K = --step, default 1) for every
// f in LIST (default: every frame of A): root position in file units and local
// rotations in degrees, both within T (default 1e-4), and the joint names.
// Without --frames and --step, the frame counts and frame times must also
// agree. Prints the largest differences. Exit 0 if equal, 3 if they differ,
// 2 on bad input (1 on an internal error).
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "motionfield.hpp"

namespace {

namespace api = motionfield;

constexpr int kExitDiffer = 3;

struct Options {
  std::string a, b;
  double tol = 1e-4;
  std::vector<int> frames;
  int step = 1;
  double units = 0.0;  // metres per file unit, 0 = detected
};

// Angle in degrees between two rotations given as (w, x, y, z) floats: the
// angle of q_a^-1 q_b, computed from its vector part (accurate near zero).
double rotation_difference_degrees(const float* a, const float* b) {
  double qa[4], qb[4], na = 0, nb = 0;
  for (int k = 0; k < 4; ++k) {
    qa[k] = a[k], qb[k] = b[k];
    na += qa[k] * qa[k], nb += qb[k] * qb[k];
  }
  na = std::sqrt(na), nb = std::sqrt(nb);
  for (int k = 0; k < 4; ++k) qa[k] /= na, qb[k] /= nb;
  // r = conj(qa) * qb
  const double w = qa[0] * qb[0] + qa[1] * qb[1] + qa[2] * qb[2] + qa[3] * qb[3];
  const double x = qa[0] * qb[1] - qa[1] * qb[0] - qa[2] * qb[3] + qa[3] * qb[2];
  const double y = qa[0] * qb[2] + qa[1] * qb[3] - qa[2] * qb[0] - qa[3] * qb[1];
  const double z = qa[0] * qb[3] - qa[1] * qb[2] + qa[2] * qb[1] - qa[3] * qb[0];
  const double angle = 2.0 * std::atan2(std::sqrt(x * x + y * y + z * z), std::abs(w));
  return angle * (180.0 / 3.14159265358979323846);
}

// Differences in the shape of the two clips (names, and with every frame compared, counts and frame times).
std::vector<std::string> shape_problems(const api::Motion& a, const api::Motion& b, bool every_frame) {
  std::vector<std::string> problems;
  if (a.joint_names() != b.joint_names()) problems.push_back("joint names differ");
  if (!every_frame) return problems;
  if (a.frame_count() != b.frame_count())
    problems.push_back("frame counts differ: " + std::to_string(a.frame_count()) + " vs " +
                       std::to_string(b.frame_count()));
  const double ta = a.frame_time(), tb = b.frame_time();
  if (std::abs(ta - tb) > 1e-6 * ta) {
    std::ostringstream s;
    s.precision(9);
    s << "frame times differ: " << ta << " vs " << tb;
    problems.push_back(s.str());
  }
  return problems;
}

struct Largest {
  double value = 0;
  int frame = -1;
  void update(double v, int f) {
    if (v > value) value = v, frame = f;
  }
};

// Compares the frames; returns the problems (empty if within the tolerance).
std::vector<std::string> compare_frames(const api::Motion& a, const api::Motion& b, const Options& o,
                                        const std::vector<int>& frames) {
  const int J = a.joint_count(), frames_a = a.frame_count(), frames_b = b.frame_count();
  const std::vector<float> rot_a = a.rotations(), rot_b = b.rotations();
  const std::vector<float> pos_a = a.root_positions(), pos_b = b.root_positions();
  const double file_units_per_metre = 1.0 / a.length_scale();
  Largest pos, rot;
  for (int f : frames) {
    const long long g = static_cast<long long>(f) * o.step;
    if (f < 0 || f >= frames_a || g >= frames_b) return {"frame " + std::to_string(f) + " is out of range"};
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += std::pow(static_cast<double>(pos_a[3 * f + k]) - pos_b[3 * g + k], 2);
    pos.update(std::sqrt(d2) * file_units_per_metre, f);
    for (int j = 0; j < J; ++j)
      rot.update(rotation_difference_degrees(&rot_a[4 * (static_cast<size_t>(f) * J + j)],
                                             &rot_b[4 * (static_cast<size_t>(g) * J + j)]),
                 f);
  }
  std::printf("compared %zu frames: max root position difference %.3g file units", frames.size(), pos.value);
  if (pos.frame >= 0) std::printf(" (frame %d)", pos.frame);
  std::printf(", max rotation difference %.3g deg", rot.value);
  if (rot.frame >= 0) std::printf(" (frame %d)", rot.frame);
  std::printf("\n");
  std::vector<std::string> problems;
  if (pos.value > o.tol) problems.push_back("root positions differ by more than the tolerance");
  if (rot.value > o.tol) problems.push_back("rotations differ by more than the tolerance");
  return problems;
}

int run(const Options& o, bool frames_given, bool step_given) {
  const api::Motion a = api::Motion::load_bvh(o.a, o.units);
  const api::Motion b = api::Motion::load_bvh(o.b, o.units);
  std::vector<std::string> problems = shape_problems(a, b, !frames_given && !step_given);
  if (problems.empty()) {
    std::vector<int> frames = o.frames;
    if (!frames_given)
      for (int f = 0; f < a.frame_count(); ++f) frames.push_back(f);
    problems = compare_frames(a, b, o, frames);
  }
  for (const std::string& p : problems) std::printf("differ: %s\n", p.c_str());
  return problems.empty() ? 0 : kExitDiffer;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("Compares two BVH files (a test aid): exit 0 if equal, 3 if they differ, 2 on bad input.",
               "mf_bvh_diff");
  Options o;
  app.add_option("a", o.a, "the first BVH file")->required();
  app.add_option("b", o.b, "the second BVH file")->required();
  app.add_option("--tol", o.tol, "tolerance of both the root position (file units) and the rotations (degrees)");
  CLI::Option* frames = app.add_option("--frames", o.frames, "frames of A to compare, e.g. 0,10,20")->delimiter(',');
  CLI::Option* step = app.add_option("--step", o.step, "frame f of A is frame f*K of B")->check(CLI::Range(1, 1 << 20));
  app.add_option("--units", o.units, "metres per file unit of both files (default: detected)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return e.get_exit_code() == 0 ? app.exit(e) : (app.exit(e), 2);
  }
  try {
    return run(o, frames->count() > 0, step->count() > 0);
  } catch (const api::Error& e) {
    std::fprintf(stderr, "mf_bvh_diff: %s\n", e.what());
    return e.status() == MF_ERROR_INTERNAL ? 1 : 2;
  }
}
