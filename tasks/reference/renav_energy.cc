#include "tasks/reference/renav_energy.h"

#include <ATen/ATen.h>

#include <string>
#include <vector>

#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/motion/kinematics_torch.h"
#include "prior/motion/rotations_torch.h"
#include "tasks/reference/soft_dtw.h"

namespace mf {

namespace {

// A window's matrix as a tensor of `shape` (no copy: valid while the window is).
at::Tensor view(const runtime::MatrixRXf& m, at::IntArrayRef shape) {
  return at::from_blob(const_cast<float*>(m.data()), shape, at::kFloat);
}

}  // namespace

RenavEnergy renav_motion_energy(const RigInfo& rig, double fps, const RenavWindow& window, const RenavWeights& w,
                                const at::Tensor& rot, const at::Tensor& root, const at::Tensor& contacts) {
  const int T = window.length;
  if (rot.dim() != 5 || rot.size(0) != 1 || rot.size(1) != T || root.dim() != 3 || root.size(1) != T)
    throw InputError("renav_motion_energy: expected rotations [1, T, J, 3, 3] and root positions [1, T, 3] with T = " +
                     std::to_string(T));
  const at::TensorOptions opt = rot.options();
  const int J = rig.num_joints(), R = static_cast<int>(window.reference_joints.rows());
  RenavEnergy out;
  auto add = [&](const char* name, double weight, const at::Tensor& value) {
    out.terms.emplace_back(name, value * weight);
  };
  if (w.path > 0) {
    at::Tensor d = ground_xz(root).squeeze(0) - view(window.target_xz, {T, 2}).to(opt);
    add("path", w.path, at::sqrt(d.square() + 1e-6).mean());
  }
  const bool use_cont = w.continuity > 0 && window.num_shared() > 0;
  at::Tensor hp;
  if (w.joints > 0 || use_cont) hp = heading_relative_positions(rot, rig);  // [1, T, J, 3]
  if (w.joints > 0) {
    add("joints", w.joints,
        soft_dtw_divergence(hp.flatten(-2), view(window.reference_joints, {1, R, J * 3}).to(opt), w.gamma).squeeze(0));
  }
  if (w.heading > 0) {
    at::Tensor h = heading_rotation(rot.select(-3, 0), rig.root_forward);  // [1, T, 3, 3]
    at::Tensor s = h.select(-2, 0).select(-1, 2), c = h.select(-2, 2).select(-1, 2);  // heading = (s, 0, c)
    at::Tensor tangent = view(window.target_tangent, {T, 2}).to(opt);
    at::Tensor signal = (s * tangent.select(-1, 0) + c * tangent.select(-1, 1)).unsqueeze(-1);  // [1, T, 1]
    const at::Tensor reference = view(window.reference_heading, {1, R, 1}).to(opt);
    add("heading", w.heading, soft_dtw_divergence(signal, reference, w.gamma).squeeze(0));
  }
  if (w.foot_skating > 0 && rig.num_feet() > 0 && T >= 2) {
    if (!contacts.defined()) throw InputError("renav_motion_energy: foot skating needs the contact probabilities");
    const at::Tensor offsets = offsets_tensor(rig.skeleton).to(opt);
    at::Tensor pos = forward_kinematics(rig.skeleton.parents, offsets, rot, root).positions;  // [1, T, J, 3]
    at::Tensor feet = at::tensor(std::vector<int64_t>(rig.foot_joints.begin(), rig.foot_joints.end()), at::kLong);
    at::Tensor fp = pos.index_select(2, feet);
    at::Tensor v = (fp.narrow(1, 1, T - 1) - fp.narrow(1, 0, T - 1)) * fps;
    at::Tensor speed2 = v.select(-1, 0).square() + v.select(-1, 2).square();
    add("foot_skating", w.foot_skating, (contacts.narrow(1, 1, T - 1).detach().to(opt) * speed2).mean());
  }
  if (use_cont) {
    const int S = window.num_shared();
    at::Tensor r = rot.squeeze(0).narrow(0, 0, S);
    at::Tensor angle = torch_rot::geodesic_angle(r, view(window.shared_rotations, {S, J, 3, 3}).to(opt));
    at::Tensor p = hp.squeeze(0).narrow(0, 0, S);
    at::Tensor d2 = (p - view(window.shared_joints, {S, J, 3}).to(opt)).square().sum(-1);
    add("continuity", w.continuity, angle.square().mean() + 10.0 * d2.mean());
  }
  out.total = at::zeros({}, opt);
  for (const auto& t : out.terms) out.total = out.total + t.second;
  return out;
}

RenavEnergy evaluate_renav_energy(const NemfModel& model, const RenavWindow& window, const RenavWeights& weights,
                                  const at::Tensor& z_l, const at::Tensor& z_g) {
  at::Tensor rot = model.decode(at::arange(window.length, at::kFloat), z_l, z_g);
  GmpOutput gmp = model.predict_global(rot, GmpUse::Steering);
  at::Tensor root = model.root_positions(rot, gmp, at::Tensor());
  at::Tensor contacts;
  if (weights.foot_skating > 0) contacts = at::sigmoid(gmp.contact_logits);
  return renav_motion_energy(model.rig(), model.config().fps, window, weights, rot, root, contacts);
}

DecodedWindow decode_renav_window(const NemfModel& model, const RenavWindow& window, const at::Tensor& z_l,
                                  const at::Tensor& z_g) {
  at::NoGradGuard no_grad;
  const int64_t T = window.length, J = model.rig().num_joints(), F = model.rig().num_feet();
  const at::Tensor rotations = model.decode(at::arange(T, at::kFloat), z_l, z_g);
  GmpOutput gmp = model.predict_global(rotations, GmpUse::Steering);
  return {rows_of(rotations, T, J * 9), rows_of(model.root_positions(rotations, gmp, at::Tensor()), T, 3),
          rows_of(at::sigmoid(gmp.contact_logits), T, F)};
}

}  // namespace mf
