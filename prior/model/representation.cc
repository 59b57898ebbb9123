#include "prior/model/representation.h"

#include <ATen/ATen.h>
#include <ATen/Dispatch.h>
#include <ATen/Parallel.h>
#include <torch/csrc/autograd/custom_function.h>

#include <algorithm>
#include <cctype>
#include <cmath>

#include "prior/motion/errors.h"
#include "prior/motion/kinematics_torch.h"
#include "prior/motion/rotation_kernels.h"
#include "prior/motion/rotations_torch.h"

namespace mf {

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  size_t k = static_cast<size_t>(p * (v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

Eigen::Matrix3d rot_y(double yaw) { return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix(); }

double heading_yaw(const Eigen::Quaterniond& root_rotation, const Eigen::Vector3d& forward) {
  Eigen::Vector3d f = root_rotation * forward;
  if (f.x() * f.x() + f.z() * f.z() < 1e-12) return 0.0;
  return std::atan2(f.x(), f.z());
}

// Rotation vector of the small relative rotation a * b^T, via its skew part.
at::Tensor skew_vector(const at::Tensor& a, const at::Tensor& b) {
  at::Tensor r = torch_rot::matmul3(a, b.transpose(-1, -2));
  return 0.5 * at::stack({r.select(-2, 2).select(-1, 1) - r.select(-2, 1).select(-1, 2),
                          r.select(-2, 0).select(-1, 2) - r.select(-2, 2).select(-1, 0),
                          r.select(-2, 1).select(-1, 0) - r.select(-2, 0).select(-1, 1)},
                         -1);
}

// Central differences along dim 1 (time), one-sided at the ends, for T >= 2.
at::Tensor time_derivative(const at::Tensor& x, double fps) {
  const int64_t T = x.size(1);
  if (T < 2) return at::zeros_like(x);
  at::Tensor prev = at::cat({x.narrow(1, 0, 1), x.narrow(1, 0, T - 1)}, 1);
  at::Tensor next = at::cat({x.narrow(1, 1, T - 1), x.narrow(1, T - 1, 1)}, 1);
  at::Tensor span = at::full({T}, 2.0, x.options());
  span.index_put_({0}, 1.0);
  span.index_put_({T - 1}, 1.0);
  std::vector<int64_t> shape(x.dim(), 1);
  shape[1] = T;
  return (next - prev) * fps / span.view(shape);
}

// The heading R_y(yaw) of each root rotation as one autograd node
// (kernels::heading_rotation and its VJP; as tensor operations it was ~17
// operators forward and as many backward, paid twice in every evaluation of a
// dense energy: the GMP's inputs and the root path).
class HeadingFunction : public torch::autograd::Function<HeadingFunction> {
 public:
  // root [N, 3, 3] contiguous float or double -> [N, 3, 3].
  static torch::autograd::variable_list forward(torch::autograd::AutogradContext* ctx, const at::Tensor& root,
                                                const Eigen::Vector3d& forward) {
    const int64_t N = root.size(0);
    at::Tensor out = at::empty({N, 3, 3}, root.options());
    AT_DISPATCH_FLOATING_TYPES(root.scalar_type(), "heading_rotation", [&] {
      const scalar_t* R = root.data_ptr<scalar_t>();
      scalar_t* H = out.data_ptr<scalar_t>();
      const scalar_t w[3] = {scalar_t(forward.x()), scalar_t(forward.y()), scalar_t(forward.z())};
      at::parallel_for(0, N, 2048, [&](int64_t n0, int64_t n1) {
        for (int64_t n = n0; n < n1; ++n) kernels::heading_rotation(R + n * 9, w, H + n * 9);
      });
    });
    ctx->save_for_backward({root});
    ctx->saved_data["forward"] = std::vector<double>{forward.x(), forward.y(), forward.z()};
    return {out};
  }

  static torch::autograd::variable_list backward(torch::autograd::AutogradContext* ctx,
                                                 torch::autograd::variable_list grads) {
    const at::Tensor root = ctx->get_saved_variables()[0];
    const std::vector<double> forward = ctx->saved_data["forward"].toDoubleVector();
    const at::Tensor g = grads[0].contiguous();
    const int64_t N = root.size(0);
    at::Tensor groot = at::empty_like(root);
    AT_DISPATCH_FLOATING_TYPES(root.scalar_type(), "heading_rotation_backward", [&] {
      const scalar_t *R = root.data_ptr<scalar_t>(), *G = g.data_ptr<scalar_t>();
      scalar_t* out = groot.data_ptr<scalar_t>();
      const scalar_t w[3] = {scalar_t(forward[0]), scalar_t(forward[1]), scalar_t(forward[2])};
      at::parallel_for(0, N, 2048, [&](int64_t n0, int64_t n1) {
        for (int64_t n = n0; n < n1; ++n) kernels::heading_rotation_vjp(R + n * 9, w, G + n * 9, out + n * 9);
      });
    });
    return {groot, at::Tensor()};
  }
};

// FK of the local motion with the heading removed from the root and the root at the origin.
FkTensors heading_free_fk(const at::Tensor& local_rotations, const RigInfo& rig) {
  at::Tensor root = local_rotations.select(-3, 0);
  at::Tensor h = heading_rotation(root, rig.root_forward);
  at::Tensor root_free = torch_rot::matmul3(h.transpose(-1, -2), root);
  at::Tensor rots = at::cat({root_free.unsqueeze(-3), local_rotations.narrow(-3, 1, local_rotations.size(-3) - 1)}, -3);
  at::Tensor offsets = offsets_tensor(rig.skeleton).to(local_rotations.options());
  at::Tensor zero_root = at::zeros(local_rotations.sizes().slice(0, local_rotations.dim() - 3), local_rotations.options())
                             .unsqueeze(-1)
                             .expand({-1, -1, 3});
  return forward_kinematics(rig.skeleton.parents, offsets, rots, zero_root);
}

}  // namespace

std::vector<int> find_foot_joints(const Skeleton& skeleton, std::vector<bool>* toe_flags) {
  std::vector<int> ankles, toes;
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    std::string n = lower(skeleton.names[j]);
    if (n.find("toe") != std::string::npos) {
      toes.push_back(j);
    } else if (n.find("foot") != std::string::npos || n.find("ankle") != std::string::npos) {
      ankles.push_back(j);
    }
  }
  std::vector<int> feet = ankles;
  feet.insert(feet.end(), toes.begin(), toes.end());
  if (toe_flags) {
    toe_flags->assign(ankles.size(), false);
    toe_flags->insert(toe_flags->end(), toes.size(), true);
  }
  return feet;
}

RigInfo measure_rig(const Skeleton& skeleton, const std::vector<const Motion*>& clips) {
  RigInfo rig;
  rig.skeleton = skeleton;
  std::vector<bool> is_toe;
  rig.foot_joints = find_foot_joints(skeleton, &is_toe);

  // Forward axis: the signed root-local axis whose ground projection follows the velocity best.
  const Eigen::Vector3d axes[6] = {Eigen::Vector3d::UnitX(),  -Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                   -Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(),  -Eigen::Vector3d::UnitZ()};
  double score[6] = {0, 0, 0, 0, 0, 0};
  std::vector<std::vector<double>> per_clip_heights(rig.foot_joints.size());
  for (const Motion* m : clips) {
    const int T = m->num_frames();
    for (int f = 0; f + 1 < T; ++f) {
      Eigen::Vector3d v = (m->root_positions[f + 1] - m->root_positions[f]) * m->fps;
      v.y() = 0;
      if (v.norm() < 0.5) continue;
      v.normalize();
      for (int a = 0; a < 6; ++a) {
        Eigen::Vector3d d = m->rotation(f, 0) * axes[a];
        d.y() = 0;
        if (d.norm() > 1e-6) score[a] += d.normalized().dot(v);
      }
    }
    if (rig.foot_joints.empty()) continue;
    GlobalPose pose = forward_kinematics(*m);
    for (size_t k = 0; k < rig.foot_joints.size(); ++k) {
      std::vector<double> h(T);
      for (int f = 0; f < T; ++f) h[f] = pose.position(f, rig.foot_joints[k]).y();
      per_clip_heights[k].push_back(percentile(h, 0.05));
    }
  }
  int best = static_cast<int>(std::max_element(score, score + 6) - score);
  if (score[best] > 0) rig.root_forward = axes[best];
  for (size_t k = 0; k < rig.foot_joints.size(); ++k) {
    rig.foot_heights.push_back(percentile(per_clip_heights[k], 0.5));
    rig.foot_thresholds.push_back(is_toe[k] ? 0.04 : 0.08);
  }
  return rig;
}

GroundTransform canonical_transform(const Motion& motion, int anchor_frame, const RigInfo& rig) {
  GroundTransform t;
  t.yaw = heading_yaw(motion.rotation(anchor_frame, 0), rig.root_forward);
  t.x = motion.root_positions[anchor_frame].x();
  t.z = motion.root_positions[anchor_frame].z();
  return t;
}

WindowTensors window_tensors(const Motion& motion, int begin, int length, const RigInfo& rig, int anchor) {
  const int J = motion.num_joints();
  if (begin < 0 || length < 1 || begin + length > motion.num_frames() || anchor < 0 || anchor >= length) {
    throw InputError("window out of the motion's range");
  }
  GroundTransform g = canonical_transform(motion, begin + anchor, rig);
  const Eigen::Matrix3d unturn = rot_y(-g.yaw);
  at::Tensor rot = at::empty({1, length, J, 3, 3}, at::kFloat);
  at::Tensor pos = at::empty({1, length, 3}, at::kFloat);
  float* r = rot.data_ptr<float>();
  float* p = pos.data_ptr<float>();
  for (int t = 0; t < length; ++t) {
    for (int j = 0; j < J; ++j) {
      Eigen::Matrix3d m = motion.rotation(begin + t, j).normalized().toRotationMatrix();
      if (j == 0) m = unturn * m;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) *r++ = static_cast<float>(m(a, b));
    }
    Eigen::Vector3d x = unturn * (motion.root_positions[begin + t] - Eigen::Vector3d(g.x, 0, g.z));
    for (int a = 0; a < 3; ++a) *p++ = static_cast<float>(x[a]);
  }
  return {rot, pos};
}

void write_window(const at::Tensor& local_rotations, const at::Tensor& root_positions,
                  const GroundTransform& transform, Motion* motion, int begin) {
  at::Tensor rot = local_rotations.detach().to(at::kDouble).contiguous();
  at::Tensor pos = root_positions.detach().to(at::kDouble).contiguous();
  if (rot.dim() == 5) rot = rot.squeeze(0);
  if (pos.dim() == 3) pos = pos.squeeze(0);
  const int T = static_cast<int>(rot.size(0));
  const int J = static_cast<int>(rot.size(1));
  if (J != motion->num_joints() || begin < 0 || begin + T > motion->num_frames()) {
    throw InputError("window does not fit the motion");
  }
  const Eigen::Matrix3d turn = rot_y(transform.yaw);
  const double* r = rot.data_ptr<double>();
  const double* p = pos.data_ptr<double>();
  for (int t = 0; t < T; ++t) {
    for (int j = 0; j < J; ++j) {
      Eigen::Matrix3d m;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) m(a, b) = *r++;
      if (j == 0) m = turn * m;
      motion->rotation(begin + t, j) = Eigen::Quaterniond(m).normalized();
    }
    Eigen::Vector3d x(p[0], p[1], p[2]);
    p += 3;
    motion->root_positions[begin + t] = turn * x + Eigen::Vector3d(transform.x, 0, transform.z);
  }
}

at::Tensor ground_xz(const at::Tensor& points) { return at::stack({points.select(-1, 0), points.select(-1, 2)}, -1); }

at::Tensor heading_rotation(const at::Tensor& root_rotations, const Eigen::Vector3d& root_forward) {
  if (!root_rotations.defined() || root_rotations.dim() < 2 || root_rotations.size(-1) != 3 ||
      root_rotations.size(-2) != 3 || !at::isFloatingType(root_rotations.scalar_type()))
    throw InputError("heading_rotation: expected floating-point root rotations [..., 3, 3]");
  const at::ScalarType work = root_rotations.scalar_type() == at::kDouble ? at::kDouble : at::kFloat;
  std::vector<int64_t> shape(root_rotations.sizes().begin(), root_rotations.sizes().end());
  return HeadingFunction::apply(root_rotations.to(work).reshape({-1, 3, 3}).contiguous(), root_forward)[0]
      .view(shape)
      .to(root_rotations.scalar_type());
}

at::Tensor trajectory_features(const at::Tensor& root_rotations, const at::Tensor& root_positions,
                               const Eigen::Vector3d& root_forward) {
  at::Tensor h = heading_rotation(root_rotations, root_forward);
  // heading_rotation is R_y(yaw): column 2 is the forward direction (sin yaw, 0, cos yaw).
  at::Tensor forward = h.select(-1, 2);
  return at::stack({root_positions.select(-1, 0), root_positions.select(-1, 2), forward.select(-1, 0),
                    forward.select(-1, 2)},
                   -1);
}

at::Tensor heading_relative_positions(const at::Tensor& local_rotations, const RigInfo& rig) {
  return heading_free_fk(local_rotations, rig).positions;
}

at::Tensor gmp_inputs(const at::Tensor& local_rotations, const RigInfo& rig) {
  at::Tensor root = local_rotations.select(-3, 0);
  at::Tensor h = heading_rotation(root, rig.root_forward);
  at::Tensor root_free = torch_rot::matrix_to_sixd(torch_rot::matmul3(h.transpose(-1, -2), root));
  at::Tensor pos = heading_relative_positions(local_rotations, rig).flatten(-2);
  return at::cat({pos, root_free}, -1);
}

at::Tensor gmp_inputs(const at::Tensor& local_rotations, const at::Tensor& positions_at_origin, const RigInfo& rig) {
  at::Tensor root = local_rotations.select(-3, 0);
  at::Tensor h_inv = heading_rotation(root, rig.root_forward).transpose(-1, -2);  // [B, T, 3, 3]
  at::Tensor root_free = torch_rot::matrix_to_sixd(torch_rot::matmul3(h_inv, root));
  // The heading is a rotation about the vertical through the origin, where the
  // root is: removing it from the root removes it from every joint's position.
  at::Tensor pos = at::matmul(positions_at_origin, h_inv.transpose(-1, -2)).flatten(-2);  // p h_inv^T = (h_inv p^T)^T
  return at::cat({pos, root_free}, -1);
}

at::Tensor local_features(const at::Tensor& local_rotations, const RigInfo& rig, double fps, at::Tensor* root6d) {
  FkTensors fk = heading_free_fk(local_rotations, rig);
  at::Tensor vel = time_derivative(fk.positions, fps);
  at::Tensor rot6 = torch_rot::matrix_to_sixd(fk.rotations);
  const int64_t T = fk.rotations.size(1);
  at::Tensor ang;
  if (T < 2) {
    ang = at::zeros_like(fk.positions);
  } else {
    at::Tensor R = fk.rotations;
    at::Tensor prev = at::cat({R.narrow(1, 0, 1), R.narrow(1, 0, T - 1)}, 1);
    at::Tensor next = at::cat({R.narrow(1, 1, T - 1), R.narrow(1, T - 1, 1)}, 1);
    at::Tensor span = at::full({T}, 2.0, R.options());
    span.index_put_({0}, 1.0);
    span.index_put_({T - 1}, 1.0);
    ang = skew_vector(next, prev) * fps / span.view({1, T, 1, 1});
  }
  if (root6d) *root6d = torch_rot::matrix_to_sixd(local_rotations.select(-3, 0));
  return at::cat({fk.positions, vel, rot6, ang}, -1);
}

GmpTargets gmp_targets(const at::Tensor& local_rotations, const at::Tensor& root_positions, const RigInfo& rig,
                       double fps) {
  const int64_t T = root_positions.size(1);
  GmpTargets out;
  at::Tensor h = heading_rotation(local_rotations.select(-3, 0), rig.root_forward);
  at::Tensor v_world;
  if (T < 2) {
    v_world = at::zeros_like(root_positions);
  } else {
    at::Tensor d = (root_positions.narrow(1, 1, T - 1) - root_positions.narrow(1, 0, T - 1)) * fps;
    v_world = at::cat({d, d.narrow(1, T - 2, 1)}, 1);
  }
  out.velocity = torch_rot::matvec3(h.transpose(-1, -2), v_world);
  out.height = root_positions.narrow(-1, 1, 1);
  if (rig.foot_joints.empty()) {
    out.contacts = at::zeros({root_positions.size(0), T, 0}, root_positions.options());
    return out;
  }
  at::Tensor offsets = offsets_tensor(rig.skeleton).to(local_rotations.options());
  FkTensors fk = forward_kinematics(rig.skeleton.parents, offsets, local_rotations, root_positions);
  std::vector<at::Tensor> contacts;
  for (int k = 0; k < rig.num_feet(); ++k) {
    at::Tensor p = fk.positions.select(-2, rig.foot_joints[k]);  // [B, T, 3]
    at::Tensor ground = ground_xz(p);
    at::Tensor speed;
    if (T < 2) {
      speed = at::zeros({p.size(0), T}, p.options());
    } else {
      at::Tensor d = (ground.narrow(1, 1, T - 1) - ground.narrow(1, 0, T - 1)).norm(2, -1) * fps;
      speed = at::cat({d, d.narrow(1, T - 2, 1)}, 1);
    }
    at::Tensor height = p.select(-1, 1) - rig.foot_heights[k];
    contacts.push_back(((height < rig.foot_thresholds[k]) & (speed < rig.contact_speed)).to(p.scalar_type()));
  }
  out.contacts = at::stack(contacts, -1);
  return out;
}

at::Tensor integrate_root(const at::Tensor& velocity, const at::Tensor& height, const at::Tensor& headings,
                          double fps, const at::Tensor& start_xz) {
  const int64_t B = velocity.size(0), T = velocity.size(1);
  at::Tensor v_world = torch_rot::matvec3(headings, velocity);
  at::Tensor step = ground_xz(v_world) / fps;
  at::Tensor start = start_xz.defined() ? start_xz.view({B, 1, 2}) : at::zeros({B, 1, 2}, velocity.options());
  at::Tensor xz = T > 1 ? at::cat({start, start + at::cumsum(step.narrow(1, 0, T - 1), 1)}, 1) : start;
  return at::stack({xz.select(-1, 0), height.select(-1, 0), xz.select(-1, 1)}, -1);
}

}  // namespace mf
