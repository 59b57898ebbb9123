// Forward kinematics on torch tensors: batched over any leading dimensions
// (windows, frames), differentiable with respect to rotations, root positions
// and offsets. Units and conventions as in skeleton.h.
#pragma once

#include <ATen/core/Tensor.h>
#include <vector>

namespace mf {

struct Skeleton;

struct FkTensors {
  at::Tensor positions;  ///< [..., J, 3] global joint positions
  at::Tensor rotations;  ///< [..., J, 3, 3] global joint rotations
};

/// local_rotations: [..., J, 3, 3]; root_positions: [..., 3]; offsets: [J, 3]
/// (row 0, the root's, is unused). parents[j] < j, parents[0] = -1.
/// The leading dimensions of local_rotations and root_positions broadcast (e.g.
/// [B, T, J, 3, 3] with [B, T, 3], or with one shared [T, 3] path). The result
/// has the promoted dtype of the inputs. Shape or parent errors throw mf::InputError.
FkTensors forward_kinematics(const std::vector<int>& parents, const at::Tensor& offsets,
                             const at::Tensor& local_rotations, const at::Tensor& root_positions);

/// The skeleton's offsets as a float [J, 3] tensor.
at::Tensor offsets_tensor(const Skeleton& skeleton);

}  // namespace mf
