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






WindowTensors window_tensors(const Motion& motion, int begin, int length, const RigInfo& rig, int anchor) {
  const WindowMatrices m = window_matrices(motion, begin, length, rig, anchor);
  const int J = motion.num_joints();
  at::Tensor rot = at::empty({1, length, J, 3, 3}, at::kFloat);
  at::Tensor pos = at::empty({1, length, 3}, at::kFloat);
  std::copy(m.local_rotations.data(), m.local_rotations.data() + m.local_rotations.size(), rot.data_ptr<float>());
  std::copy(m.root_positions.data(), m.root_positions.data() + m.root_positions.size(), pos.data_ptr<float>());
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
  if (rot.dim() != 4 || pos.dim() != 2 || pos.size(0) != T || pos.size(1) != 3)
    throw InputError("write_window: expected rotations [T, J, 3, 3] and root positions [T, 3]");
  using Rows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  write_window(Eigen::Map<const Rows>(rot.data_ptr<double>(), T, J * 9),
               Eigen::Map<const Rows>(pos.data_ptr<double>(), T, 3), transform, motion, begin);
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
