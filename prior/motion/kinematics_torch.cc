#include "prior/motion/kinematics_torch.h"

#include <ATen/ATen.h>
#include <ATen/ExpandUtils.h>

#include <algorithm>
#include <string>
#include <vector>

#include "prior/motion/errors.h"
#include "prior/motion/skeleton.h"

namespace mf {
namespace {

std::string shape_string(const at::Tensor& t) {
  std::string s = "[";
  for (int64_t i = 0; i < t.dim(); ++i) s += (i ? ", " : "") + std::to_string(t.size(i));
  return s + "]";
}

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

  // matmul does not promote dtypes: bring everything to the common one.
  const at::ScalarType dtype =
      at::promote_types(at::promote_types(local_rotations.scalar_type(), root_positions.scalar_type()),
                        offsets.scalar_type());
  const at::TensorOptions opts = local_rotations.options().dtype(dtype);
  std::vector<int64_t> rot_shape = batch, pos_shape = batch;
  rot_shape.insert(rot_shape.end(), {J, 3, 3});
  pos_shape.push_back(3);
  const at::Tensor local = local_rotations.to(opts).expand(rot_shape);
  const at::Tensor root = root_positions.to(opts).expand(pos_shape);
  const at::Tensor offs = offsets.to(opts);

  // Joints are processed a tree level at a time (every parent lies on the level
  // before its children), so a humanoid's ~22 joints take ~8 batched steps
  // instead of 22: FK runs in every energy evaluation of the latent solvers,
  // and its per-op overhead, not its arithmetic, is what costs; at::matmul's
  // backward is also cheaper than that of torch_rot::matmul3's broadcast
  // product (bench/fk_cost.cc: forward + backward over 128 frames about half the
  // time of the joint-by-joint loop). No in-place writes into tensors that
  // autograd needs.
  std::vector<int> level(static_cast<size_t>(J), 0);
  int depth = 0;
  for (int64_t j = 1; j < J; ++j) depth = std::max(depth, level[j] = level[static_cast<size_t>(parents[j])] + 1);
  std::vector<std::vector<int64_t>> members(static_cast<size_t>(depth) + 1);
  std::vector<int64_t> slot(static_cast<size_t>(J));  // index of a joint within its level
  for (int64_t j = 0; j < J; ++j) {
    slot[j] = static_cast<int64_t>(members[level[j]].size());
    members[level[j]].push_back(j);
  }
  const auto index = [](const std::vector<int64_t>& v) { return at::tensor(v, at::kLong); };
  std::vector<at::Tensor> level_rot{local.narrow(-3, 0, 1)}, level_pos{root.unsqueeze(-2)};
  std::vector<int64_t> order{0};
  for (int d = 1; d <= depth; ++d) {
    const std::vector<int64_t>& joints = members[static_cast<size_t>(d)];
    std::vector<int64_t> parent_slots;
    for (int64_t j : joints) parent_slots.push_back(slot[static_cast<size_t>(parents[j])]);
    const at::Tensor ps = index(parent_slots), js = index(joints);
    const at::Tensor parent_rot = level_rot.back().index_select(-3, ps);
    level_rot.push_back(at::matmul(parent_rot, local.index_select(-3, js)));
    level_pos.push_back(level_pos.back().index_select(-2, ps) +
                        at::matmul(parent_rot, offs.index_select(0, js).unsqueeze(-1)).squeeze(-1));
    order.insert(order.end(), joints.begin(), joints.end());
  }
  std::vector<int64_t> inverse(static_cast<size_t>(J));
  for (int64_t i = 0; i < J; ++i) inverse[static_cast<size_t>(order[i])] = i;
  const at::Tensor back = index(inverse);
  return {at::cat(level_pos, -2).index_select(-2, back), at::cat(level_rot, -3).index_select(-3, back)};
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
