// The NeMF prior's model file, libtorch side: a NemfModel's tensors written
// to and read from the container of model_container.h (its layout, parsing and
// validation, torch-free), which this header includes.
#pragma once

#include <ATen/core/Tensor.h>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "prior/model/model_container.h"
#include "prior/model/nemf.h"

namespace mf {

/// The bytes of a model file of `kind` (model_container.h's layout); tensors
/// (any dtype, converted to float32) are written in the given order.
std::vector<uint8_t> serialize_model_file(const std::string& kind, const std::map<std::string, double>& hyperparameters,
                                          const RigInfo& rig,
                                          const std::vector<std::pair<std::string, at::Tensor>>& tensors);
/// Copies tensor `name` of `tensors` into `target` (same shape required; a
/// new tensor when `target` is undefined) and removes it from the map;
/// throws InputError when missing or misshapen.
void take_model_tensor(std::map<std::string, StoredTensor>& tensors, const std::string& name, at::Tensor& target,
                       const std::string& source);

std::vector<uint8_t> serialize_nemf(const NemfModel& model);
/// The prior stored by serialize_nemf(), frozen (set_requires_grad(false)): the
/// trainer unfreezes it to continue training.
NemfModel deserialize_nemf(const uint8_t* data, size_t size, const std::string& source);

void save_nemf(const NemfModel& model, const std::string& path);
NemfModel load_nemf(const std::string& path);

}  // namespace mf
