#include "tasks/reference/energies.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/motion/kinematics_torch.h"
#include "prior/motion/rotations_torch.h"
#include "tasks/constraints/residual_bracket.h"
#include "tasks/context/task_context.h"

namespace mf {
namespace {

// sum(values * mask) / count, count > 0 known by the caller.
at::Tensor masked_mean(const at::Tensor& values, const at::Tensor& mask, double count) {
  return (values * mask).sum() / count;
}

// Squared penalty of a residual given as its square (d2) or as a non-negative value.
at::Tensor penalty_of_squared(const at::Tensor& d2, Penalty p) {
  return p == Penalty::Squared ? d2 : at::sqrt(d2 + 1e-12);
}
at::Tensor penalty_of_angle(const at::Tensor& angle, Penalty p) {
  return p == Penalty::Squared ? angle.square() : angle;
}

}  // namespace

// ---------------------------------------------------------------------------
// Window problems

int WindowProblem::num_trajectory() const {
  return trajectory_frames.defined() ? static_cast<int>(trajectory_frames.size(0)) : 0;
}
int WindowProblem::num_keys() const { return key_frames.defined() ? static_cast<int>(key_frames.size(0)) : 0; }
int WindowProblem::num_pin_steps() const { return pin_from.defined() ? static_cast<int>(pin_from.size(0)) : 0; }

int WindowProblem::num_effectors() const {
  return effector_frames.defined() ? static_cast<int>(effector_frames.size(0)) : 0;
}

namespace {

at::Tensor long_tensor(const std::vector<int>& v) {
  return at::tensor(std::vector<int64_t>(v.begin(), v.end()), at::kLong);
}

// A float matrix as a tensor of `shape`.
at::Tensor float_tensor(const runtime::MatrixRXf& m, at::IntArrayRef shape) {
  return at::from_blob(const_cast<float*>(m.data()), {static_cast<int64_t>(m.size())}, at::kFloat)
      .clone()
      .reshape(shape);
}
at::Tensor float_tensor(const Eigen::VectorXf& v) {
  return at::from_blob(const_cast<float*>(v.data()), {static_cast<int64_t>(v.size())}, at::kFloat).clone();
}

}  // namespace

WindowProblem to_tensor_problem(const RuntimeWindowProblem& r, int J) {
  WindowProblem p;
  const int64_t K = r.num_keys(), E = r.num_effectors(), R = r.num_trajectory();
  p.length = r.length;
  p.anchor = r.anchor;
  p.transform = r.transform;
  p.key_frames = long_tensor(r.key_frames);
  p.key_rotations = float_tensor(r.key_rotations, {K, J, 3, 3});
  p.key_rotation_mask = float_tensor(r.key_rotation_mask, {K, J});
  p.key_positions = float_tensor(r.key_positions, {K, J, 3});
  p.key_position_mask = float_tensor(r.key_position_mask, {K, J});
  p.key_root = float_tensor(r.key_root, {K, 3});
  p.key_root_mask = float_tensor(r.key_root_mask);
  p.effector_frames = long_tensor(r.effector_frames);
  p.effector_joints = long_tensor(r.effector_joints);
  p.effector_targets = float_tensor(r.effector_targets, {E, 3});
  p.effector_weights = float_tensor(r.effector_weights);
  p.pin_from = long_tensor(r.pin_from);
  p.pin_to = long_tensor(r.pin_to);
  p.trajectory_frames = long_tensor(r.trajectory_frames);
  p.trajectory_ground = float_tensor(r.trajectory_ground, {R, 2});
  p.trajectory_forward = float_tensor(r.trajectory_forward, {R, 2});
  return p;
}

namespace {

// The values of an int64 tensor of n entries.
std::vector<int> ints_of(const at::Tensor& t, int n) {
  if (n == 0) return {};
  const at::Tensor c = t.to(at::kLong).contiguous();
  return std::vector<int>(c.data_ptr<int64_t>(), c.data_ptr<int64_t>() + n);
}

}  // namespace

RuntimeWindowProblem to_runtime_problem(const WindowProblem& problem, int joints) {
  RuntimeWindowProblem p;
  const int K = problem.num_keys(), J = joints;
  p.length = problem.length;
  p.anchor = problem.anchor;
  p.transform = problem.transform;
  p.key_frames = ints_of(problem.key_frames, K);
  p.key_rotations = rows_of(problem.key_rotations, K, J * 9);
  p.key_rotation_mask = rows_of(problem.key_rotation_mask, K, J);
  p.key_positions = rows_of(problem.key_positions, K, J * 3);
  p.key_position_mask = rows_of(problem.key_position_mask, K, J);
  p.key_root = rows_of(problem.key_root, K, 3);
  p.key_root_mask = rows_of(problem.key_root_mask, K, 1).col(0);
  const int E = problem.num_effectors(), P = problem.num_pin_steps(), R = problem.num_trajectory();
  p.effector_frames = ints_of(problem.effector_frames, E);
  p.effector_joints = ints_of(problem.effector_joints, E);
  p.effector_targets = rows_of(problem.effector_targets, E, 3);
  p.effector_weights = rows_of(problem.effector_weights, E, 1).col(0);
  p.pin_from = ints_of(problem.pin_from, P);
  p.pin_to = ints_of(problem.pin_to, P);
  p.trajectory_frames = ints_of(problem.trajectory_frames, R);
  p.trajectory_ground = rows_of(problem.trajectory_ground, R, 2);
  p.trajectory_forward = rows_of(problem.trajectory_forward, R, 2);
  return p;
}

WindowProblem make_window_problem(const RigInfo& rig, const Motion& motion, int begin, int length,
                                  const MotionConstraints& constraints, int anchor) {
  return to_tensor_problem(make_runtime_problem(rig, motion, begin, length, constraints, anchor), rig.num_joints());
}

// ---------------------------------------------------------------------------
// Energies

namespace {

// The root path of a dense decode from its GMP output, its ground position at
// the anchor moved to the anchor key's (the canonical origin).
at::Tensor aligned_root_path(const NemfModel& model, const WindowProblem& problem, const at::Tensor& rotations,
                             const GmpOutput& gmp) {
  at::Tensor path = model.root_positions(rotations, gmp);  // [1, T, 3], starts at the origin
  at::Tensor xz_mask = at::tensor({1.0f, 0.0f, 1.0f}, path.options());
  at::Tensor shift = path.select(1, problem.anchor) * xz_mask;  // [1, 3]
  return path - shift.unsqueeze(1);
}

// Where each frame takes its residual from: the keys a and b around it that
// constrain the joint (or the root position) and the smoothstep weight of b.
struct Brackets {
  at::Tensor a, b;  // [n] int64 key indices
  at::Tensor s;     // [n] float
  at::Tensor has;   // [n] float: 0 where no key constrains the joint
};

// key_frame[k] = frame of key k; on[k] = whether key k constrains the series
// (key_brackets(), tasks/constraints/residual_bracket.h), written with `stride`.
void bracket_series(const std::vector<int>& key_frame, const std::vector<char>& on, int T, int64_t* a, int64_t* b,
                    float* s, float* has, int64_t stride) {
  std::vector<KeyBracket> brackets;
  key_brackets(key_frame, on, T, &brackets);
  for (int f = 0; f < T; ++f) {
    const int64_t i = static_cast<int64_t>(f) * stride;
    a[i] = brackets[f].a;
    b[i] = brackets[f].b;
    s[i] = brackets[f].s;
    has[i] = brackets[f].has ? 1.0f : 0.0f;
  }
}

// Brackets of every (frame, joint) [T * J] and of the root position [T].
void residual_brackets(const WindowProblem& p, int J, Brackets* joints, Brackets* root) {
  const int K = p.num_keys(), T = p.length;
  const at::Tensor key_frames = p.key_frames.contiguous();
  const std::vector<int> frames(key_frames.data_ptr<int64_t>(), key_frames.data_ptr<int64_t>() + K);
  const at::Tensor rmask = p.key_rotation_mask.contiguous();
  const float* m = rmask.data_ptr<float>();
  auto alloc = [](Brackets* br, int64_t n) {
    br->a = at::empty({n}, at::kLong);
    br->b = at::empty({n}, at::kLong);
    br->s = at::empty({n}, at::kFloat);
    br->has = at::empty({n}, at::kFloat);
  };
  alloc(joints, static_cast<int64_t>(T) * J);
  alloc(root, T);
  std::vector<char> on(K);
  for (int j = 0; j < J; ++j) {
    for (int k = 0; k < K; ++k) on[k] = m[k * J + j] > 0;
    bracket_series(frames, on, T, joints->a.data_ptr<int64_t>() + j, joints->b.data_ptr<int64_t>() + j,
                   joints->s.data_ptr<float>() + j, joints->has.data_ptr<float>() + j, J);
  }
  const at::Tensor rootmask = p.key_root_mask.contiguous();
  for (int k = 0; k < K; ++k) on[k] = rootmask.data_ptr<float>()[k] > 0;
  bracket_series(frames, on, T, root->a.data_ptr<int64_t>(), root->b.data_ptr<int64_t>(), root->s.data_ptr<float>(),
                 root->has.data_ptr<float>(), 1);
}

// The window after the known-value overwrite of complete_motion(): the
// residual at each key, blended between keys with smoothstep weights (the same
// rule, in float and differentiable). rotations [1, T, J, 3, 3], path [1, T, 3].
void blend_residuals(const WindowProblem& p, const at::Tensor& rotations, const at::Tensor& path,
                     at::Tensor* out_rotations, at::Tensor* out_path) {
  const int K = p.num_keys(), T = p.length;
  const int J = static_cast<int>(rotations.size(2));
  if (K == 0) {
    *out_rotations = rotations;
    *out_path = path;
    return;
  }
  Brackets bj, br;
  residual_brackets(p, J, &bj, &br);
  const at::TensorOptions opt = rotations.options();
  at::Tensor raw_keys = rotations.squeeze(0).index_select(0, p.key_frames);  // [K, J, 3, 3]
  at::Tensor residual = torch_rot::matrix_to_quat(
      torch_rot::matmul3(p.key_rotations.to(opt), raw_keys.transpose(-1, -2)));  // [K, J, 4]
  at::Tensor flat = residual.reshape({K * J, 4});
  at::Tensor joint_index = at::arange(J, at::kLong).repeat({T});
  at::Tensor qa = flat.index_select(0, bj.a * J + joint_index);
  at::Tensor qb = flat.index_select(0, bj.b * J + joint_index);
  at::Tensor q = torch_rot::quat_slerp(qa, qb, bj.s.unsqueeze(-1));  // [T * J, 4]
  at::Tensor identity = at::tensor({1.0f, 0.0f, 0.0f, 0.0f}, opt);
  at::Tensor has = bj.has.unsqueeze(-1);
  q = q * has + identity * (1 - has);
  *out_rotations = torch_rot::matmul3(torch_rot::quat_to_matrix(q).view({1, T, J, 3, 3}), rotations);
  at::Tensor d = p.key_root - path.squeeze(0).index_select(0, p.key_frames);  // [K, 3]
  at::Tensor s = br.s.unsqueeze(-1);
  at::Tensor correction = (d.index_select(0, br.a) * (1 - s) + d.index_select(0, br.b) * s) * br.has.unsqueeze(-1);
  *out_path = path + correction.unsqueeze(0);
}

}  // namespace

namespace {

// The items of each term in `problem` (TermCounts).
ActiveTerms active_terms(const RigInfo& rig, const WindowProblem& problem, const EnergyWeights& w) {
  const int J = rig.num_joints();
  TermCounts c;
  if (problem.num_keys() > 0) {
    c.rotations = problem.key_rotation_mask.narrow(1, 1, J - 1).sum().item<double>();
    c.root_rotations = problem.key_rotation_mask.select(1, 0).sum().item<double>();
    c.positions = problem.key_position_mask.sum().item<double>();
    c.root_positions = problem.key_root_mask.sum().item<double>();
  }
  c.effectors = problem.num_effectors();
  c.pin_steps = problem.num_pin_steps();
  c.trajectory_rows = problem.num_trajectory();
  c.feet = rig.num_feet();
  c.length = problem.length;
  return active_terms(c, w);
}

void add_term(EnergyTerms* out, const char* name, double weight, const at::Tensor& value) {
  out->terms.emplace_back(name, value * weight);
}

// The terms at the key frames: rotation, root orientation, position.
// key_rot [K, J, 3, 3] decoded at the key frames; key_pos [K, J, 3] their
// joint positions with the root at the origin when already computed (else
// undefined).
void add_key_terms(const Skeleton& skel, const WindowProblem& problem, const EnergyWeights& w, const ActiveTerms& a,
                   const at::Tensor& key_rot, const at::Tensor& key_pos, const at::Tensor& offsets, EnergyTerms* out) {
  const int J = skel.num_joints(), K = problem.num_keys();
  const at::TensorOptions opt = offsets.options();  // the codes' (evaluate_energy)
  if (a.rot || a.root_rot) {
    at::Tensor pen = penalty_of_angle(torch_rot::geodesic_angle(key_rot, problem.key_rotations.to(opt)), w.penalty);
    if (a.rot) {
      add_term(out, "rotation", w.rotation,
               masked_mean(pen.narrow(1, 1, J - 1), problem.key_rotation_mask.narrow(1, 1, J - 1), a.n_rot));
    }
    if (a.root_rot) {
      add_term(out, "root_orientation", w.root_orientation,
               masked_mean(pen.select(1, 0), problem.key_rotation_mask.select(1, 0), a.n_root_rot));
    }
  }
  if (a.pos) {
    at::Tensor p =
        key_pos.defined() ? key_pos : forward_kinematics(skel.parents, offsets, key_rot, at::zeros({K, 3}, opt)).positions;
    at::Tensor d2 = (p - problem.key_positions).square().sum(-1);  // [K, J]
    add_term(out, "position", w.position,
             masked_mean(penalty_of_squared(d2, w.penalty), problem.key_position_mask, a.n_pos));
  }
}

// The trajectory terms on the output motion: ground position and facing of the
// root at the rows' frames. rotations [1, T, J, 3, 3], path [1, T, 3].
void add_trajectory_terms(const RigInfo& rig, const WindowProblem& problem, const EnergyWeights& w,
                          const ActiveTerms& a, const at::Tensor& rotations, const at::Tensor& path, EnergyTerms* out) {
  const at::Tensor frames = problem.trajectory_frames;
  const at::Tensor root = rotations.squeeze(0).index_select(0, frames).select(1, 0);  // [R, 3, 3]
  const at::Tensor features = trajectory_features(root, path.squeeze(0).index_select(0, frames), rig.root_forward);
  if (a.traj) {
    at::Tensor d2 = (features.narrow(-1, 0, 2) - problem.trajectory_ground).square().sum(-1);
    add_term(out, "trajectory", w.trajectory, penalty_of_squared(d2, w.penalty).mean());
  }
  if (a.facing) {
    at::Tensor d2 = (features.narrow(-1, 2, 2) - problem.trajectory_forward).square().sum(-1);
    add_term(out, "trajectory_facing", w.trajectory_facing, penalty_of_squared(d2, w.penalty).mean());
  }
}

// The terms on the output motion (see EnergyWeights::on_output): effector,
// foot skating, smoothness. rotations [1, T, J, 3, 3], path [1, T, 3];
// positions_at_origin [1, T, J, 3] the FK of rotations with the root at the origin.
void add_output_terms(const NemfModel& model, const WindowProblem& problem, const EnergyWeights& w,
                      const ActiveTerms& a, const at::Tensor& rotations, const at::Tensor& path,
                      const at::Tensor& positions_at_origin, const GmpOutput& gmp, const at::Tensor& offsets,
                      EnergyTerms* out) {
  const RigInfo& rig = model.rig();
  const int J = rig.num_joints(), T = problem.length, E = problem.num_effectors();
  const double fps = model.config().fps;
  at::Tensor out_rot = rotations, out_path = path;
  const bool blended = w.on_output && problem.num_keys() > 0;
  if (blended) blend_residuals(problem, rotations, path, &out_rot, &out_path);
  at::Tensor pos = blended ? forward_kinematics(rig.skeleton.parents, offsets, out_rot, out_path).positions
                           : positions_at_origin + out_path.unsqueeze(2);  // [1, T, J, 3]
  if (a.eff) {
    at::Tensor idx = problem.effector_frames * J + problem.effector_joints;
    at::Tensor p = pos.reshape({T * J, 3}).index_select(0, idx);
    at::Tensor d2 = (p - problem.effector_targets).square().sum(-1);
    add_term(out, "effector", w.effector, (penalty_of_squared(d2, w.penalty) * problem.effector_weights).sum() / E);
  }
  if (a.pin) {
    at::Tensor flat = pos.reshape({T * J, 3});
    at::Tensor v = (flat.index_select(0, problem.pin_to) - flat.index_select(0, problem.pin_from)) * fps;
    add_term(out, "contact", w.contact, penalty_of_squared(v.square().sum(-1), w.penalty).mean());
  }
  if (a.traj || a.facing) add_trajectory_terms(rig, problem, w, a, out_rot, out_path, out);
  if (a.skate) {
    at::Tensor feet = at::tensor(std::vector<int64_t>(rig.foot_joints.begin(), rig.foot_joints.end()), at::kLong);
    at::Tensor fp = pos.index_select(2, feet);                             // [1, T, F, 3]
    at::Tensor v = (fp.narrow(1, 1, T - 1) - fp.narrow(1, 0, T - 1)) * fps;  // [1, T-1, F, 3]
    at::Tensor speed2 = v.select(-1, 0).square() + v.select(-1, 2).square();
    at::Tensor contact = at::sigmoid(gmp.contact_logits.narrow(1, 1, T - 1)).detach();
    add_term(out, "foot_skating", w.foot_skating, (contact * speed2).mean());
  }
  if (a.smooth) {
    at::Tensor rel = pos - out_path.unsqueeze(2);
    at::Tensor acc = (rel.narrow(1, 2, T - 2) - 2 * rel.narrow(1, 1, T - 2) + rel.narrow(1, 0, T - 2)) * (fps * fps);
    add_term(out, "smoothness", w.smoothness, acc.square().sum(-1).mean());
  }
}

// The terms on the whole window: root translation, then the output terms.
// dense_rot [1, T, J, 3, 3] decoded at every frame, dense_pos [1, T, J, 3] its
// FK with the root at the origin.
void add_dense_terms(const NemfModel& model, const WindowProblem& problem, const EnergyWeights& w,
                     const ActiveTerms& a, const at::Tensor& dense_rot, const at::Tensor& dense_pos,
                     const at::Tensor& offsets, EnergyTerms* out) {
  GmpOutput gmp = model.predict_global_from_inputs(gmp_inputs(dense_rot, dense_pos, model.rig()));
  at::Tensor path = aligned_root_path(model, problem, dense_rot, gmp);  // [1, T, 3]
  if (a.root) {
    at::Tensor d2 = (path.squeeze(0).index_select(0, problem.key_frames) - problem.key_root).square().sum(-1);
    add_term(out, "root_translation", w.root_translation,
             masked_mean(penalty_of_squared(d2, w.penalty), problem.key_root_mask, a.n_root));
  }
  if (a.eff || a.pin || a.traj || a.facing || a.skate || a.smooth) add_output_terms(model, problem, w, a, dense_rot, path, dense_pos, gmp, offsets, out);
}

}  // namespace

EnergyTerms evaluate_energy(const NemfModel& model, const WindowProblem& problem, const EnergyWeights& w,
                            const at::Tensor& z_l, const at::Tensor& z_g) {
  const RigInfo& rig = model.rig();
  const ActiveTerms a = active_terms(rig, problem, w);
  const at::TensorOptions opt = z_l.options();
  EnergyTerms out;
  // Decode the whole window when a dense term needs it (the key frames then
  // gathered from it), else only the key frames. One FK pass of the dense
  // decode serves the GMP's input, the key positions and the output terms.
  const at::Tensor offsets = offsets_tensor(rig.skeleton).to(opt);
  at::Tensor dense_rot, dense_pos, key_rot, key_pos;
  if (a.dense) {
    dense_rot = model.decode(at::arange(problem.length, at::kFloat), z_l, z_g);  // [1, T, J, 3, 3]
    dense_pos = forward_kinematics(rig.skeleton.parents, offsets, dense_rot, at::zeros({1, problem.length, 3}, opt))
                    .positions;  // [1, T, J, 3]
    if (a.keyed) {
      key_rot = dense_rot.index_select(1, problem.key_frames).squeeze(0);
      key_pos = dense_pos.index_select(1, problem.key_frames).squeeze(0);
    }
  } else if (a.keyed) {
    key_rot = model.decode(problem.key_frames.to(at::kFloat), z_l, z_g).squeeze(0);  // [K, J, 3, 3]
  }
  if (a.keyed) add_key_terms(rig.skeleton, problem, w, a, key_rot, key_pos, offsets, &out);
  if (a.dense) add_dense_terms(model, problem, w, a, dense_rot, dense_pos, offsets, &out);
  if (w.latent_prior > 0) add_term(&out, "latent_prior", w.latent_prior, 0.5 * (z_l.square().sum() + z_g.square().sum()));
  out.total = at::zeros({}, opt);
  for (const auto& t : out.terms) out.total = out.total + t.second;
  return out;
}

DecodedWindow decode_window(const NemfModel& model, const WindowProblem& problem, const at::Tensor& z_l,
                            const at::Tensor& z_g) {
  at::NoGradGuard no_grad;
  const int64_t T = problem.length, J = model.rig().num_joints(), F = model.rig().num_feet();
  const at::Tensor rotations = model.decode(at::arange(T, at::kFloat), z_l, z_g);
  GmpOutput gmp = model.predict_global(rotations);
  return {rows_of(rotations, T, J * 9), rows_of(aligned_root_path(model, problem, rotations, gmp), T, 3),
          rows_of(at::sigmoid(gmp.contact_logits), T, F)};
}

}  // namespace mf
