// The terms of the Eigen runtime's energy on the output motion (effector,
// contact, trajectory, trajectory_facing, foot_skating, smoothness):
// add_output_terms and add_trajectory_terms of tasks/latent/energies.cc,
// with their gradients, in the same order and with the same means.
#include <cmath>
#include <utility>

#include "prior/motion/rotation_kernels.h"
#include "tasks/latent/runtime_energy.h"
#include "tasks/latent/runtime_penalties.h"

namespace mf {
namespace {

using runtime::MatrixRXf;
using runtime_penalties::Penalised;
using runtime_penalties::squared_penalty;
using Row3 = Eigen::Matrix<float, 1, 3>;

// The second difference's frames (after t) and coefficients.
constexpr std::pair<int, float> kSecondDifference[] = {{0, 1.0f}, {1, -2.0f}, {2, 1.0f}};

}  // namespace

// The output motion: the dense decode with the keys' residuals blended in
// (EnergyWeights::on_output, when the problem has keys), else as decoded;
// its joint positions with the root on the path.
void RuntimeEnergy::output_motion(const RuntimeWindowProblem& p, const EnergyWeights& w) {
  const int T = p.length, J = kinematics_.joints();
  blended_ = w.on_output && p.num_keys() > 0;
  if (blended_) {
    blend_.forward(p, rotations_, path_, &blended_rotations_, &out_path_);
    kinematics_.forward(blended_rotations_, out_path_, &out_positions_, &out_globals_);
  } else {
    out_path_ = path_;
    out_positions_ = positions_;
    for (int t = 0; t < T; ++t) {
      for (int j = 0; j < J; ++j) out_positions_.row(t).segment<3>(j * 3) += out_path_.row(t);
    }
  }
  if (gradient_) {
    g_out_rotations_.setZero(T, J * 9);
    g_out_path_.setZero(T, 3);
    g_out_positions_.setZero(T, J * 3);
  }
}

void RuntimeEnergy::add_output_terms(const RuntimeWindowProblem& p, const EnergyWeights& w, const ActiveTerms& a,
                                     RuntimeEnergyTerms* out) {
  output_motion(p, w);
  if (a.eff) add_effector(p, w, out);
  if (a.pin) add_contact(p, w, out);
  if (a.traj || a.facing) add_trajectory(p, w, a, out);
  if (a.skate) add_foot_skating(w, out);
  if (a.smooth) add_smoothness(w, out);
  if (gradient_) output_motion_vjp(p);
}

// effector: the weighted penalty of each target's distance, summed, over E.
void RuntimeEnergy::add_effector(const RuntimeWindowProblem& p, const EnergyWeights& w, RuntimeEnergyTerms* out) {
  const int E = p.num_effectors();
  double sum = 0;
  for (int e = 0; e < E; ++e) {
    const int f = p.effector_frames[e], j = p.effector_joints[e];
    const Row3 d = out_positions_.row(f).segment<3>(j * 3) - p.effector_targets.row(e);
    const Penalised pen = squared_penalty(d.squaredNorm(), w.penalty);
    sum += pen.value * p.effector_weights[e];
    if (gradient_) {
      g_out_positions_.row(f).segment<3>(j * 3) +=
          static_cast<float>(w.effector / E * p.effector_weights[e] * pen.slope * 2) * d;
    }
  }
  out->terms.emplace_back("effector", w.effector * sum / E);
}

// contact: the mean penalty of the pinned joints' squared velocity.
void RuntimeEnergy::add_contact(const RuntimeWindowProblem& p, const EnergyWeights& w, RuntimeEnergyTerms* out) {
  const int J = kinematics_.joints(), P = p.num_pin_steps();
  const float fps = static_cast<float>(model_->config().fps);
  double sum = 0;
  for (int i = 0; i < P; ++i) {
    const int from = p.pin_from[i], to = p.pin_to[i];
    const Row3 v = (out_positions_.row(to / J).segment<3>(to % J * 3) -
                    out_positions_.row(from / J).segment<3>(from % J * 3)) *
                   fps;
    const Penalised pen = squared_penalty(v.squaredNorm(), w.penalty);
    sum += pen.value;
    if (!gradient_) continue;
    const Row3 g = static_cast<float>(w.contact / P * pen.slope * 2 * fps) * v;
    g_out_positions_.row(to / J).segment<3>(to % J * 3) += g;
    g_out_positions_.row(from / J).segment<3>(from % J * 3) -= g;
  }
  out->terms.emplace_back("contact", w.contact * sum / P);
}

// trajectory and trajectory_facing: the root's ground position and facing
// (trajectory_features(), representation.h: column 2 of its heading) against
// each row's, mean penalties over the rows.
void RuntimeEnergy::add_trajectory(const RuntimeWindowProblem& p, const EnergyWeights& w, const ActiveTerms& a,
                                   RuntimeEnergyTerms* out) {
  const int R = p.num_trajectory();
  const MatrixRXf& rotations = out_rotations();
  double sum_ground = 0, sum_facing = 0;
  for (int r = 0; r < R; ++r) {
    const int f = p.trajectory_frames[r];
    if (a.traj) {
      const Eigen::Vector2f d(out_path_(f, 0) - p.trajectory_ground(r, 0), out_path_(f, 2) - p.trajectory_ground(r, 1));
      const Penalised pen = squared_penalty(d.squaredNorm(), w.penalty);
      sum_ground += pen.value;
      const float g = static_cast<float>(w.trajectory / R * pen.slope * 2);
      if (gradient_) g_out_path_(f, 0) += g * d.x(), g_out_path_(f, 2) += g * d.y();
    }
    if (!a.facing) continue;
    float h[9];
    kernels::heading_rotation(&rotations(f, 0), root_forward_.data(), h);
    const Eigen::Vector2f d(h[2] - p.trajectory_forward(r, 0), h[8] - p.trajectory_forward(r, 1));
    const Penalised pen = squared_penalty(d.squaredNorm(), w.penalty);
    sum_facing += pen.value;
    if (!gradient_) continue;
    const float g = static_cast<float>(w.trajectory_facing / R * pen.slope * 2);
    float g_h[9] = {}, g_root[9];
    g_h[2] = g * d.x();
    g_h[8] = g * d.y();
    kernels::heading_rotation_vjp(&rotations(f, 0), root_forward_.data(), g_h, g_root);
    for (int i = 0; i < 9; ++i) g_out_rotations_(f, i) += g_root[i];
  }
  if (a.traj) out->terms.emplace_back("trajectory", w.trajectory * sum_ground / R);
  if (a.facing) out->terms.emplace_back("trajectory_facing", w.trajectory_facing * sum_facing / R);
}

// foot_skating: RuntimeDecodePass::foot_skating() on the output motion.
void RuntimeEnergy::add_foot_skating(const EnergyWeights& w, RuntimeEnergyTerms* out) {
  const double value = foot_skating(out_positions_, w.foot_skating, &g_out_positions_);
  out->terms.emplace_back("foot_skating", w.foot_skating * value);
}

// smoothness: the mean squared second difference of the root-relative joint
// positions (m/s^2).
void RuntimeEnergy::add_smoothness(const EnergyWeights& w, RuntimeEnergyTerms* out) {
  const int T = static_cast<int>(out_positions_.rows()), J = kinematics_.joints();
  const float fps2 = static_cast<float>(model_->config().fps * model_->config().fps);
  const double n = static_cast<double>(T - 2) * J;
  auto rel = [&](int t, int j) -> Row3 { return out_positions_.row(t).segment<3>(j * 3) - out_path_.row(t); };
  double sum = 0;
  for (int t = 0; t + 2 < T; ++t) {
    for (int j = 0; j < J; ++j) {
      const Row3 acc = (rel(t + 2, j) - 2.0f * rel(t + 1, j) + rel(t, j)) * fps2;
      sum += acc.squaredNorm();
      if (!gradient_) continue;
      const Row3 g = static_cast<float>(w.smoothness / n * 2 * fps2) * acc;
      for (const auto& [dt, c] : kSecondDifference) {
        g_out_positions_.row(t + dt).segment<3>(j * 3) += c * g;
        g_out_path_.row(t + dt).head<3>() -= c * g;
      }
    }
  }
  out->terms.emplace_back("smoothness", w.smoothness * sum / n);
}

// The gradient of output_motion(): from the output motion's gradients to the
// decoded rotations, their root-at-origin positions and the root path.
void RuntimeEnergy::output_motion_vjp(const RuntimeWindowProblem& p) {
  if (blended_) {
    kinematics_.vjp(blended_rotations_, out_globals_, g_out_positions_, nullptr, &g_local_, &g_root_);
    g_out_rotations_ += g_local_;
    g_out_path_ += g_root_;
    blend_.vjp(p, rotations_, g_out_rotations_, g_out_path_, &g_rotations_, &g_path_);
    return;
  }
  g_rotations_ += g_out_rotations_;
  g_positions_ += g_out_positions_;
  g_path_ += g_out_path_;
  const int T = static_cast<int>(g_out_positions_.rows()), J = kinematics_.joints();
  for (int t = 0; t < T; ++t) {
    for (int j = 0; j < J; ++j) g_path_.row(t) += g_out_positions_.row(t).segment<3>(j * 3);
  }
}

}  // namespace mf
