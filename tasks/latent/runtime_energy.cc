#include "tasks/latent/runtime_energy.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "prior/motion/errors.h"
#include "prior/motion/rotation_kernels.h"
#include "tasks/latent/runtime_penalties.h"

namespace mf {
namespace {

using runtime_penalties::angle_penalty;
using runtime_penalties::Penalised;
using runtime_penalties::squared_penalty;

TermCounts term_counts(const RuntimeWindowProblem& p, int J, int feet) {
  TermCounts c;
  if (p.num_keys() > 0) {
    c.rotations = p.key_rotation_mask.rightCols(J - 1).sum();
    c.root_rotations = p.key_rotation_mask.col(0).sum();
    c.positions = p.key_position_mask.sum();
    c.root_positions = p.key_root_mask.sum();
  }
  c.effectors = p.num_effectors();
  c.pin_steps = p.num_pin_steps();
  c.trajectory_rows = p.num_trajectory();
  c.feet = feet;
  c.length = p.length;
  return c;
}

// Throws unless every index of the effectors, pins and trajectory rows lies
// inside the window of J joints and their targets have their sizes.
void check_output_constraints(const RuntimeWindowProblem& p, int J) {
  const int T = p.length, E = p.num_effectors(), R = p.num_trajectory();
  auto inside = [](const std::vector<int>& v, int end) {
    return std::all_of(v.begin(), v.end(), [end](int i) { return i >= 0 && i < end; });
  };
  if (static_cast<int>(p.effector_joints.size()) != E || p.effector_targets.rows() != E ||
      (E > 0 && p.effector_targets.cols() != 3) || p.effector_weights.size() != E || !inside(p.effector_frames, T) ||
      !inside(p.effector_joints, J))
    throw InputError("runtime energy: the end-effector targets do not fit the window");
  if (p.pin_to.size() != p.pin_from.size() || !inside(p.pin_from, T * J) || !inside(p.pin_to, T * J))
    throw InputError("runtime energy: the contact pins do not fit the window");
  if (p.trajectory_ground.rows() != R || p.trajectory_forward.rows() != R ||
      (R > 0 && (p.trajectory_ground.cols() != 2 || p.trajectory_forward.cols() != 2)) ||
      !inside(p.trajectory_frames, T))
    throw InputError("runtime energy: the trajectory rows do not fit the window");
}

void check_problem(const RuntimeWindowProblem& p, int J, int window) {
  const Eigen::Index K = p.num_keys();
  if (p.length < 2 || p.length > window || p.anchor < 0 || p.anchor >= p.length)
    throw InputError("runtime energy: a window of 2 to " + std::to_string(window) +
                     " frames with its anchor inside it is required");
  for (int f : p.key_frames) {
    if (f < 0 || f >= p.length) throw InputError("runtime energy: a key lies outside its window");
  }
  if (p.key_rotations.rows() != K || p.key_rotations.cols() != J * 9 || p.key_rotation_mask.rows() != K ||
      p.key_rotation_mask.cols() != J || p.key_positions.rows() != K || p.key_positions.cols() != J * 3 ||
      p.key_position_mask.rows() != K || p.key_position_mask.cols() != J || p.key_root.rows() != K ||
      p.key_root.cols() != 3 || p.key_root_mask.size() != K)
    throw InputError("runtime energy: the keys' targets do not match " + std::to_string(K) + " keys of " +
                     std::to_string(J) + " joints");
  check_output_constraints(p, J);
}

}  // namespace

RuntimeEnergy::RuntimeEnergy(const runtime::NemfRuntime& model)
    : RuntimeDecodePass(model) {}

RuntimeEnergyTerms RuntimeEnergy::evaluate(const RuntimeWindowProblem& problem, const EnergyWeights& w,
                                           const Eigen::Ref<const Eigen::VectorXf>& z_l,
                                           const Eigen::Ref<const Eigen::VectorXf>& z_g, Eigen::VectorXf* g_zl,
                                           Eigen::VectorXf* g_zg) {
  const RigInfo& rig = model_->rig();
  const NemfConfig& config = model_->config();
  check_problem(problem, rig.num_joints(), config.window);
  if (z_l.size() != config.zl || z_g.size() != config.zg)
    throw InputError("runtime energy: expected z_l [" + std::to_string(config.zl) + "] and z_g [" +
                     std::to_string(config.zg) + "]");
  const ActiveTerms a = active_terms(term_counts(problem, rig.num_joints(), rig.num_feet()), w);
  gradient_ = g_zl != nullptr && g_zg != nullptr;
  RuntimeEnergyTerms out;
  const bool decoded = a.keyed || a.dense;
  if (decoded) decode_rows(problem, a, z_l, z_g);
  if (a.keyed) add_key_terms(problem, w, a, &out);
  if (a.dense) add_dense_terms(problem, w, a, &out);
  if (w.latent_prior > 0)
    out.terms.emplace_back("latent_prior", w.latent_prior * 0.5 * (z_l.squaredNorm() + z_g.squaredNorm()));
  for (const auto& t : out.terms) out.total += t.second;
  if (!gradient_) return out;
  if (decoded) {
    backward(a.dense || a.pos, g_zl, g_zg);
  } else {
    g_zl->setZero(config.zl);
    g_zg->setZero(config.zg);
  }
  if (w.latent_prior > 0) {
    *g_zl += static_cast<float>(w.latent_prior) * z_l;
    *g_zg += static_cast<float>(w.latent_prior) * z_g;
  }
  return out;
}

DecodedWindow RuntimeEnergy::decode_window(const RuntimeWindowProblem& problem,
                                           const Eigen::Ref<const Eigen::VectorXf>& z_l,
                                           const Eigen::Ref<const Eigen::VectorXf>& z_g) {
  check_problem(problem, model_->rig().num_joints(), model_->config().window);
  ActiveTerms dense;
  dense.dense = true;
  gradient_ = false;
  decode_rows(problem, dense, z_l, z_g);
  predict(GmpUse::Default, problem.anchor);
  const int F = model_->rig().num_feet();
  runtime::MatrixRXf contacts = (1.0f / (1.0f + (-gmp_out_.rightCols(F).array()).exp())).matrix();
  return {rotations_, path_, std::move(contacts)};
}

// Decodes the whole window when a dense term is active, else the key frames,
// and runs FK (root at the origin) when a term reads positions.
void RuntimeEnergy::decode_rows(const RuntimeWindowProblem& problem, const ActiveTerms& a,
                                const Eigen::Ref<const Eigen::VectorXf>& z_l,
                                const Eigen::Ref<const Eigen::VectorXf>& z_g) {
  const int S = a.dense ? problem.length : problem.num_keys();
  frames_.resize(S);
  for (int s = 0; s < S; ++s) frames_[s] = a.dense ? s : problem.key_frames[s];
  decode(frames_, z_l, z_g, a.dense || a.pos);
}

// rotation, root_orientation and position at the keys: means over the
// constrained items, as add_key_terms in energies.cc.
void RuntimeEnergy::add_key_terms(const RuntimeWindowProblem& p, const EnergyWeights& w, const ActiveTerms& a,
                                  RuntimeEnergyTerms* out) {
  const int J = kinematics_.joints();
  double sum_rot = 0, sum_root = 0, sum_pos = 0;
  for (int k = 0; k < p.num_keys(); ++k) {
    const int row = a.dense ? p.key_frames[k] : k;
    for (int j = 0; j < J && (a.rot || a.root_rot); ++j) {
      const float mask = p.key_rotation_mask(k, j);
      if (mask == 0 || !(j == 0 ? a.root_rot : a.rot)) continue;
      const float* decoded = &rotations_(row, j * 9);
      const Penalised pen = angle_penalty(kernels::geodesic_angle(decoded, &p.key_rotations(k, j * 9)), w.penalty);
      (j == 0 ? sum_root : sum_rot) += mask * pen.value;
      if (!gradient_) continue;
      const double scale = j == 0 ? w.root_orientation / a.n_root_rot : w.rotation / a.n_rot;
      float g[9];
      kernels::geodesic_angle_vjp(decoded, &p.key_rotations(k, j * 9), static_cast<float>(scale * mask * pen.slope), g,
                                  static_cast<float*>(nullptr));
      g_rotations_.row(row).segment<9>(j * 9) += Eigen::Map<const Eigen::Matrix<float, 1, 9>>(g);
    }
    for (int j = 0; j < J && a.pos; ++j) {
      const float mask = p.key_position_mask(k, j);
      if (mask == 0) continue;
      const Eigen::Matrix<float, 1, 3> d =
          positions_.row(row).segment<3>(j * 3) - p.key_positions.row(k).segment<3>(j * 3);
      const Penalised pen = squared_penalty(d.squaredNorm(), w.penalty);
      sum_pos += mask * pen.value;
      if (gradient_) {
        g_positions_.row(row).segment<3>(j * 3) += static_cast<float>(w.position / a.n_pos * mask * pen.slope * 2) * d;
      }
    }
  }
  if (a.rot) out->terms.emplace_back("rotation", w.rotation * sum_rot / a.n_rot);
  if (a.root_rot) out->terms.emplace_back("root_orientation", w.root_orientation * sum_root / a.n_root_rot);
  if (a.pos) out->terms.emplace_back("position", w.position * sum_pos / a.n_pos);
}

// The terms on the dense decode: the GMP on it and its root path, then
// root_translation and the output terms (runtime_energy_output.cc), and
// their gradient back to the decoded rotations and positions.
void RuntimeEnergy::add_dense_terms(const RuntimeWindowProblem& p, const EnergyWeights& w, const ActiveTerms& a,
                                    RuntimeEnergyTerms* out) {
  predict(GmpUse::Default, p.anchor);
  if (a.root) add_root_translation(p, w, a, out);
  if (a.eff || a.pin || a.traj || a.facing || a.skate || a.smooth) add_output_terms(p, w, a, out);
  if (!gradient_) return;
  predict_vjp(GmpUse::Default, p.anchor);
}

// root_translation: the root path against the keys' root positions.
void RuntimeEnergy::add_root_translation(const RuntimeWindowProblem& p, const EnergyWeights& w, const ActiveTerms& a,
                                         RuntimeEnergyTerms* out) {
  double sum = 0;
  for (int k = 0; k < p.num_keys(); ++k) {
    const float mask = p.key_root_mask[k];
    if (mask == 0) continue;
    const int f = p.key_frames[k];
    const Eigen::Matrix<float, 1, 3> d = path_.row(f) - p.key_root.row(k);
    const Penalised pen = squared_penalty(d.squaredNorm(), w.penalty);
    sum += mask * pen.value;
    if (gradient_)
      g_path_.row(f).head<3>() += static_cast<float>(w.root_translation / a.n_root * mask * pen.slope * 2) * d;
  }
  out->terms.emplace_back("root_translation", w.root_translation * sum / a.n_root);
}

}  // namespace mf
