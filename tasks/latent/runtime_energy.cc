#include "tasks/latent/runtime_energy.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "prior/motion/errors.h"
#include "prior/motion/rotation_kernels.h"
#include "prior/runtime/root_path.h"
#include "prior/runtime/rotations.h"
#include "tasks/latent/runtime_penalties.h"

namespace mf {
namespace {

using runtime::MatrixRXf;
using Matrix3 = Eigen::Matrix<float, 3, 3, Eigen::RowMajor>;
using Map3 = Eigen::Map<Matrix3>;
using ConstMap3 = Eigen::Map<const Matrix3>;
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
    : model_(&model), kinematics_(model.rig().skeleton), root_forward_(model.rig().root_forward.cast<float>()) {}

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
  if (decoded) decode(problem, a, z_l, z_g);
  if (a.keyed) add_key_terms(problem, w, a, &out);
  if (a.dense) add_dense_terms(problem, w, a, &out);
  if (w.latent_prior > 0)
    out.terms.emplace_back("latent_prior", w.latent_prior * 0.5 * (z_l.squaredNorm() + z_g.squaredNorm()));
  for (const auto& t : out.terms) out.total += t.second;
  if (!gradient_) return out;
  if (decoded) {
    backward(a, g_zl, g_zg);
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
  decode(problem, dense, z_l, z_g);
  gmp_inputs();
  model_->predict_global(gmp_in_, GmpUse::Default, &gmp_ws_, &gmp_out_);
  root_path(problem.anchor);
  const int F = model_->rig().num_feet();
  runtime::MatrixRXf contacts = (1.0f / (1.0f + (-gmp_out_.rightCols(F).array()).exp())).matrix();
  return {rotations_, path_, std::move(contacts)};
}

// Decodes the whole window when a dense term is active, else the key frames,
// and runs FK (root at the origin) when a term reads positions.
void RuntimeEnergy::decode(const RuntimeWindowProblem& problem, const ActiveTerms& a,
                           const Eigen::Ref<const Eigen::VectorXf>& z_l, const Eigen::Ref<const Eigen::VectorXf>& z_g) {
  const int S = a.dense ? problem.length : problem.num_keys(), J = kinematics_.joints();
  frames_.resize(S);
  for (int s = 0; s < S; ++s) frames_[s] = a.dense ? s : problem.key_frames[s];
  model_->decode(frames_, z_l, z_g, &decoder_ws_, &sixd_);
  runtime::sixd_to_matrix(sixd_, &rotations_);
  if (a.dense || a.pos) {
    zero_root_.setZero(S, 3);
    kinematics_.forward(rotations_, zero_root_, &positions_, &globals_);
  }
  if (gradient_) {
    g_rotations_.setZero(S, J * 9);
    g_positions_.setZero(S, J * 3);
  }
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
  gmp_inputs();
  model_->predict_global(gmp_in_, GmpUse::Default, &gmp_ws_, &gmp_out_);
  root_path(p.anchor);
  if (gradient_) g_path_.setZero(p.length, 3);
  if (a.root) add_root_translation(p, w, a, out);
  if (a.eff || a.pin || a.traj || a.facing || a.skate || a.smooth) add_output_terms(p, w, a, out);
  if (!gradient_) return;
  root_path_vjp(p.anchor);
  model_->predict_global_vjp(&gmp_ws_, GmpUse::Default, g_gmp_out_, &g_gmp_in_);
  gmp_inputs_vjp();
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

// gmp_inputs() of representation.h from the dense decode (prior/runtime/root_path.h).
void RuntimeEnergy::gmp_inputs() { runtime::gmp_inputs(rotations_, positions_, root_forward_, &headings_, &gmp_in_); }

// NemfModel::root_positions() (prior/runtime/root_path.h) then the alignment
// of energies.cc: the ground position at the anchor moved to the origin.
void RuntimeEnergy::root_path(int anchor) {
  runtime::integrate_root_path(headings_, gmp_out_, model_->config().fps, &path_);
  const float ax = path_(anchor, 0), az = path_(anchor, 2);
  path_.col(0).array() -= ax;
  path_.col(2).array() -= az;
}

// The gradient of root_path(): from g_path_ to the GMP's outputs (g_gmp_out_)
// and the headings (g_headings_, started here).
void RuntimeEnergy::root_path_vjp(int anchor) {
  const int T = static_cast<int>(gmp_out_.rows());
  const float fps = static_cast<float>(model_->config().fps);
  g_gmp_out_.setZero(T, gmp_out_.cols());
  g_headings_.setZero(T, 9);
  g_path_(anchor, 0) -= g_path_.col(0).sum();
  g_path_(anchor, 2) -= g_path_.col(2).sum();
  float later_x = 0, later_z = 0;  // the ground gradient of the frames after t: frame t's step feeds them
  for (int t = T - 1; t >= 0; --t) {
    const Eigen::Vector3f g_world(later_x / fps, 0.0f, later_z / fps);
    const ConstMap3 h(&headings_(t, 0));
    g_gmp_out_.row(t).head<3>() = (h.transpose() * g_world).transpose();
    Map3(&g_headings_(t, 0)) += g_world * gmp_out_.row(t).head<3>();
    g_gmp_out_(t, 3) = g_path_(t, 1);
    later_x += g_path_(t, 0);
    later_z += g_path_(t, 2);
  }
}

// The gradient of gmp_inputs(): from g_gmp_in_ (and the headings' gradient)
// to the decoded rotations and positions.
void RuntimeEnergy::gmp_inputs_vjp() {
  const int T = static_cast<int>(rotations_.rows()), J = kinematics_.joints();
  for (int t = 0; t < T; ++t) {
    const ConstMap3 h(&headings_(t, 0)), root(&rotations_(t, 0));
    Map3 g_h(&g_headings_(t, 0)), g_root(&g_rotations_(t, 0));
    for (int j = 0; j < J; ++j) {
      const Eigen::Vector3f g = g_gmp_in_.row(t).segment<3>(j * 3).transpose();
      g_positions_.row(t).segment<3>(j * 3) += (h * g).transpose();
      g_h += positions_.row(t).segment<3>(j * 3).transpose() * g.transpose();
    }
    Matrix3 g_free = Matrix3::Zero();
    g_free.col(0) = g_gmp_in_.row(t).segment<3>(J * 3).transpose();
    g_free.col(1) = g_gmp_in_.row(t).segment<3>(J * 3 + 3).transpose();
    g_root += h * g_free;
    g_h += root * g_free.transpose();
    Matrix3 g_from_heading;
    kernels::heading_rotation_vjp(&rotations_(t, 0), root_forward_.data(), &g_headings_(t, 0), g_from_heading.data());
    g_root += g_from_heading;
  }
}

// From the gradients of the decoded rotations and positions to the latents.
void RuntimeEnergy::backward(const ActiveTerms& a, Eigen::VectorXf* g_zl, Eigen::VectorXf* g_zg) {
  if (a.dense || a.pos) {
    kinematics_.vjp(rotations_, globals_, g_positions_, nullptr, &g_local_, &g_root_);
    g_rotations_ += g_local_;
  }
  runtime::sixd_to_matrix_vjp(sixd_, g_rotations_, &g_sixd_);
  model_->decode_vjp(&decoder_ws_, g_sixd_, g_zl, g_zg);
}

}  // namespace mf
