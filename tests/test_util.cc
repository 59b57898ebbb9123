#include "tests/test_util.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <fstream>
#include <random>

namespace mf::test {

Skeleton small_skeleton() {
  Skeleton s;
  s.names = {"Hips", "Spine", "Head", "UpperLeg_L", "Foot_L", "UpperLeg_R", "Foot_R"};
  s.parents = {-1, 0, 1, 0, 3, 0, 5};
  s.offsets = {{0, 0, 0},    {0, 0.2, 0},   {0, 0.4, 0}, {0.1, -0.05, 0},
               {0, -0.8, 0}, {-0.1, -0.05, 0}, {0, -0.8, 0}};
  return s;
}

bool all_finite(const Motion& m) {
  for (const auto& p : m.root_positions)
    if (!p.allFinite()) return false;
  for (const auto& q : m.rotations)
    if (!q.coeffs().allFinite()) return false;
  return true;
}

double max_abs_difference(const Motion& a, const Motion& b) {
  double d = 0.0;
  for (size_t i = 0; i < a.rotations.size(); ++i)
    d = std::max(d, (a.rotations[i].coeffs() - b.rotations[i].coeffs()).cwiseAbs().maxCoeff());
  for (size_t i = 0; i < a.root_positions.size(); ++i)
    d = std::max(d, (a.root_positions[i] - b.root_positions[i]).cwiseAbs().maxCoeff());
  return d;
}

Motion random_motion(const Skeleton& skeleton, int frames, double fps, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Motion m = Motion::identity(skeleton, frames, fps);
  const int J = skeleton.num_joints();
  // Each channel is a sum of two sinusoids with random frequency and phase.
  for (int j = 0; j < J; ++j) {
    Eigen::Vector3d a1(u(rng), u(rng), u(rng)), a2(u(rng), u(rng), u(rng));
    Eigen::Vector3d w1 = Eigen::Vector3d(u(rng), u(rng), u(rng)).cwiseAbs() * 3.0;
    Eigen::Vector3d w2 = Eigen::Vector3d(u(rng), u(rng), u(rng)).cwiseAbs() * 7.0;
    for (int f = 0; f < frames; ++f) {
      double t = f / fps;
      Eigen::Vector3d aa;
      for (int k = 0; k < 3; ++k) aa[k] = 0.8 * a1[k] * std::sin(w1[k] * t + k) + 0.3 * a2[k] * std::cos(w2[k] * t);
      double angle = aa.norm();
      m.rotation(f, j) = angle < 1e-12 ? Eigen::Quaterniond::Identity()
                                       : Eigen::Quaterniond(Eigen::AngleAxisd(angle, aa / angle));
    }
  }
  double vx = u(rng), vz = u(rng);
  for (int f = 0; f < frames; ++f) {
    double t = f / fps;
    m.root_positions[f] = Eigen::Vector3d(vx * t, 0.9 + 0.05 * std::sin(6.0 * t), vz * t + 0.2 * std::sin(2.0 * t));
  }
  return m;
}

NemfConfig tiny_nemf_config() {
  NemfConfig c;
  c.window = 32;
  c.decoder_width = 32;
  c.decoder_layers = 3;
  c.zl = 8;
  c.zg = 4;
  c.zg_layers = 2;
  c.encoder_channels = 4;
  c.gmp_width = 8;
  c.gmp_blocks = 1;
  return c;
}

RigInfo tiny_rig() {
  Skeleton s = small_skeleton();
  Motion m = random_motion(s, 60, 30.0, 3);
  return measure_rig(s, {&m});
}

NemfModel tiny_prior(uint64_t seed, const NemfConfig& config, const RigInfo& rig) {
  at::manual_seed(seed);
  NemfModel model(config, rig);
  model.set_requires_grad(false);
  return model;
}

std::unique_ptr<InbetweenModel> tiny_transformer(const std::string& kind, const RigInfo& rig, uint64_t seed) {
  at::manual_seed(seed);
  std::map<std::string, double> hp = {{"width", 16}, {"layers", 1}, {"heads", 2}, {"ffn", 32}, {"window", 32}};
  if (kind == kCitlKind) hp["time_dim"] = 4;
  return make_inbetweener(kind, hp, rig);
}

std::string scratch_dir(const std::string& name) {
  namespace fs = std::filesystem;
  fs::path p = fs::path(MF_BINARY_DIR) / "test-scratch" / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

std::vector<double> log_column(const std::string& path, const std::string& name) {
  std::ifstream in(path);
  std::string line, cell;
  std::getline(in, line);
  std::stringstream header(line);
  int col = -1, k = 0;
  while (std::getline(header, cell, ',')) {
    if (cell == name) col = k;
    ++k;
  }
  std::vector<double> out;
  while (col >= 0 && std::getline(in, line)) {
    std::stringstream row(line);
    for (int i = 0; std::getline(row, cell, ','); ++i)
      if (i == col) out.push_back(std::stod(cell));
  }
  return out;
}

at::Tensor window_rotations(const DecodedWindow& d) {
  const int64_t T = d.local_rotations.rows(), J = d.local_rotations.cols() / 9;
  return at::from_blob(const_cast<float*>(d.local_rotations.data()), {T, J, 3, 3}, at::kFloat).clone();
}

at::Tensor window_root_positions(const DecodedWindow& d) {
  const int64_t T = d.root_positions.rows();
  return at::from_blob(const_cast<float*>(d.root_positions.data()), {T, 3}, at::kFloat).clone();
}

}  // namespace mf::test
