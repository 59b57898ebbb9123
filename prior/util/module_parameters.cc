#include "prior/util/module_parameters.h"

#include <torch/nn/module.h>

namespace mf {

std::vector<std::pair<std::string, at::Tensor>> named_parameters_of(const torch::nn::Module& module) {
  std::vector<std::pair<std::string, at::Tensor>> out;
  for (const auto& item : module.named_parameters(true)) out.emplace_back(item.key(), item.value());
  return out;
}

}  // namespace mf
