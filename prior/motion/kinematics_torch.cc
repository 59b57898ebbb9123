#include "prior/motion/kinematics_torch.h"

#include <ATen/ATen.h>
#include <ATen/Dispatch.h>
#include <ATen/ExpandUtils.h>
#include <ATen/Parallel.h>
#include <torch/csrc/autograd/custom_function.h>

#include <algorithm>
#include <string>
#include <vector>

#include "prior/motion/errors.h"
#include "prior/motion/kinematics_kernels.h"
#include "prior/motion/skeleton.h"

namespace mf {
namespace {

std::string shape_string(const at::Tensor& t) {
  std::string s = "[";
  for (int64_t i = 0; i < t.dim(); ++i) s += (i ? ", " : "") + std::to_string(t.size(i));
  return s + "]";
}

// The kinematic chain as one autograd node with the hand-written backward of
// kinematics_kernels.h (shared with the Eigen runtime). FK runs in every
// energy evaluation of the latent solvers, where a batched formulation (a few
// tensor operations per tree level) cost about 2 ms per forward + backward
// over 128 frames, nearly all of it per-operation framework overhead; the
// arithmetic is ~100 flops per joint and frame (bench/fk_cost.cc compares it
// with a joint-by-joint autograd reference).
// Frames per parallel task: a humanoid's FK costs about a microsecond per frame.
constexpr int64_t kGrain = 64;

class FkFunction : public torch::autograd::Function<FkFunction> {
 public:
  // local [N, J, 3, 3], root [N, 3], offsets [J, 3]: contiguous, one float type.
  static torch::autograd::variable_list forward(torch::autograd::AutogradContext* ctx, const at::Tensor& local,
                                                const at::Tensor& root, const at::Tensor& offsets,
                                                const std::vector<int>& parents) {
    const int64_t N = local.size(0), J = local.size(1);
    at::Tensor P = at::empty({N, J, 3}, local.options()), R = at::empty({N, J, 3, 3}, local.options());
    AT_DISPATCH_FLOATING_TYPES(local.scalar_type(), "forward_kinematics", [&] {
      const scalar_t *l = local.data_ptr<scalar_t>(), *rt = root.data_ptr<scalar_t>(), *o = offsets.data_ptr<scalar_t>();
      scalar_t *p = P.data_ptr<scalar_t>(), *r = R.data_ptr<scalar_t>();
      at::parallel_for(0, N, kGrain,
                       [&](int64_t n0, int64_t n1) { kernels::fk_forward(l, rt, o, parents.data(), J, n0, n1, p, r); });
    });
    ctx->save_for_backward({local, offsets, R});
    ctx->saved_data["parents"] = c10::List<int64_t>(std::vector<int64_t>(parents.begin(), parents.end()));
    return {P, R};
  }

  static torch::autograd::variable_list backward(torch::autograd::AutogradContext* ctx,
                                                 torch::autograd::variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const at::Tensor &local = saved[0], &offsets = saved[1], &R = saved[2];
    const c10::List<int64_t> list = ctx->saved_data["parents"].toIntList();
    const std::vector<int> parents(list.begin(), list.end());
    const int64_t N = local.size(0), J = local.size(1);
    const at::Tensor gP = grads[0].defined() ? grads[0].contiguous() : at::zeros({N, J, 3}, local.options());
    const at::Tensor gR = grads[1].defined() ? grads[1].contiguous() : at::zeros({N, J, 3, 3}, local.options());
    at::Tensor gL = at::empty_like(local), gRoot = at::empty({N, 3}, local.options());
    at::Tensor gO = at::empty({N, J, 3}, local.options());  // per frame, summed below (deterministic)
    AT_DISPATCH_FLOATING_TYPES(local.scalar_type(), "forward_kinematics_backward", [&] {
      const scalar_t *l = local.data_ptr<scalar_t>(), *o = offsets.data_ptr<scalar_t>(), *r = R.data_ptr<scalar_t>();
      const scalar_t *gp = gP.data_ptr<scalar_t>(), *gr = gR.data_ptr<scalar_t>();
      scalar_t *gl = gL.data_ptr<scalar_t>(), *groot = gRoot.data_ptr<scalar_t>(), *go = gO.data_ptr<scalar_t>();
      at::parallel_for(0, N, kGrain, [&](int64_t n0, int64_t n1) {
        std::vector<scalar_t> acc_p(static_cast<size_t>(J) * 3), acc_r(static_cast<size_t>(J) * 9);
        kernels::fk_backward(l, o, r, gp, gr, parents.data(), J, n0, n1, gl, groot, go, acc_p, acc_r);
      });
    });
    return {gL, gRoot, gO.sum(0), at::Tensor()};
  }
};

}  // namespace

FkTensors forward_kinematics(const std::vector<int>& parents, const at::Tensor& offsets,
                             const at::Tensor& local_rotations, const at::Tensor& root_positions) {
  const int64_t J = static_cast<int64_t>(parents.size());
  if (J == 0) throw InputError("forward_kinematics: the skeleton has no joints");
  if (!local_rotations.defined() || local_rotations.dim() < 3 || local_rotations.size(-3) != J ||
      local_rotations.size(-2) != 3 || local_rotations.size(-1) != 3)
    throw InputError("forward_kinematics: local_rotations must have shape [..., " + std::to_string(J) +
                     ", 3, 3], got " + (local_rotations.defined() ? shape_string(local_rotations) : "undefined"));
  if (!offsets.defined() || offsets.dim() != 2 || offsets.size(0) != J || offsets.size(1) != 3)
    throw InputError("forward_kinematics: offsets must have shape [" + std::to_string(J) + ", 3], got " +
                     (offsets.defined() ? shape_string(offsets) : "undefined"));
  if (!root_positions.defined() || root_positions.dim() < 1 || root_positions.size(-1) != 3)
    throw InputError("forward_kinematics: root_positions must have shape [..., 3], got " +
                     (root_positions.defined() ? shape_string(root_positions) : "undefined"));
  if (parents[0] != -1) throw InputError("forward_kinematics: joint 0 must be the root (parent -1)");
  for (int64_t j = 1; j < J; ++j)
    if (parents[j] < 0 || parents[j] >= j)
      throw InputError("forward_kinematics: joint " + std::to_string(j) + " has parent " +
                       std::to_string(parents[j]) + "; every parent must come before its child");

  const at::IntArrayRef rot_batch = local_rotations.sizes().slice(0, local_rotations.dim() - 3);
  const at::IntArrayRef root_batch = root_positions.sizes().slice(0, root_positions.dim() - 1);
  std::vector<int64_t> batch;
  try {
    batch = at::infer_size(rot_batch, root_batch);
  } catch (const std::exception&) {
    throw InputError("forward_kinematics: leading shapes of local_rotations " + shape_string(local_rotations) +
                     " and root_positions " + shape_string(root_positions) + " do not broadcast");
  }

  // Computed in double for double inputs and in float otherwise.
  const at::ScalarType dtype =
      at::promote_types(at::promote_types(local_rotations.scalar_type(), root_positions.scalar_type()),
                        offsets.scalar_type());
  const at::ScalarType work = dtype == at::kDouble ? at::kDouble : at::kFloat;
  const at::TensorOptions opts = local_rotations.options().dtype(work);
  std::vector<int64_t> rot_shape = batch, pos_shape = batch;
  rot_shape.insert(rot_shape.end(), {J, 3, 3});
  pos_shape.push_back(3);
  const at::Tensor local = local_rotations.to(opts).expand(rot_shape).reshape({-1, J, 3, 3}).contiguous();
  const at::Tensor root = root_positions.to(opts).expand(pos_shape).reshape({-1, 3}).contiguous();
  const at::Tensor offs = offsets.to(opts).contiguous();
  const torch::autograd::variable_list out = FkFunction::apply(local, root, offs, parents);
  std::vector<int64_t> out_pos = batch, out_rot = batch;
  out_pos.insert(out_pos.end(), {J, 3});
  out_rot.insert(out_rot.end(), {J, 3, 3});
  return {out[0].view(out_pos).to(dtype), out[1].view(out_rot).to(dtype)};
}

at::Tensor offsets_tensor(const Skeleton& skeleton) {
  const int64_t J = static_cast<int64_t>(skeleton.offsets.size());
  at::Tensor out = at::empty({J, 3}, at::kFloat);
  auto acc = out.accessor<float, 2>();
  for (int64_t j = 0; j < J; ++j)
    for (int64_t k = 0; k < 3; ++k) acc[j][k] = static_cast<float>(skeleton.offsets[static_cast<size_t>(j)][k]);
  return out;
}

}  // namespace mf
