#include "prior/motion/kinematics_torch.h"

#include <ATen/ATen.h>
#include <ATen/ExpandUtils.h>

#include <string>

#include "prior/motion/errors.h"
#include "prior/motion/rotations_torch.h"
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

  // Per-joint tensors gathered in vectors and stacked once: no in-place writes
  // into tensors that autograd needs.
  std::vector<at::Tensor> rotations(static_cast<size_t>(J)), positions(static_cast<size_t>(J));
  rotations[0] = local.select(-3, 0);
  positions[0] = root;
  for (int64_t j = 1; j < J; ++j) {
    const at::Tensor& parent_rot = rotations[static_cast<size_t>(parents[j])];
    rotations[j] = torch_rot::matmul3(parent_rot, local.select(-3, j));
    positions[j] = positions[static_cast<size_t>(parents[j])] + torch_rot::matvec3(parent_rot, offs[j]);
  }
  return {at::stack(positions, -2), at::stack(rotations, -3)};
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
