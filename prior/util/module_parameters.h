// The parameters of a libtorch module as the model files store them.
#pragma once

#include <ATen/core/Tensor.h>

#include <string>
#include <utility>
#include <vector>

namespace torch::nn {
class Module;
}

namespace mf {

/// Every parameter of `module` and its submodules, by its stable dotted name
/// ("layers.0.attn.q.weight", ...), in registration order: the keys and order
/// of the model files (prior/model/model_file.h, prior/inbetween/inbetweener.h).
std::vector<std::pair<std::string, at::Tensor>> named_parameters_of(const torch::nn::Module& module);

}  // namespace mf
