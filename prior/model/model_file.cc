#include "prior/model/model_file.h"

#include <ATen/ATen.h>

#include <cstring>

#include "prior/motion/errors.h"
#include "prior/util/binary_io.h"
#include "prior/util/file_writer.h"

namespace mf {

namespace {

std::vector<std::pair<std::string, at::Tensor>> stats_tensors(const NemfStats& s) {
  return {{"stats.feature_mean", s.feature_mean}, {"stats.feature_std", s.feature_std},
          {"stats.root_mean", s.root_mean},       {"stats.root_std", s.root_std},
          {"stats.gmp_in_mean", s.gmp_in_mean},   {"stats.gmp_in_std", s.gmp_in_std},
          {"stats.gmp_out_mean", s.gmp_out_mean}, {"stats.gmp_out_std", s.gmp_out_std}};
}

}  // namespace

std::vector<uint8_t> serialize_model_file(const std::string& kind, const std::map<std::string, double>& hyperparameters,
                                          const RigInfo& rig,
                                          const std::vector<std::pair<std::string, at::Tensor>>& tensors) {
  std::vector<at::Tensor> contiguous;  // keeps the float32 copies alive while writing
  std::vector<TensorToWrite> views;
  for (const auto& [name, t] : tensors) {
    contiguous.push_back(t.detach().to(at::kFloat).contiguous());
    views.push_back({name, contiguous.back().sizes().vec(), contiguous.back().data_ptr<float>()});
  }
  return serialize_model_container(kind, hyperparameters, rig, views);
}

void take_model_tensor(std::map<std::string, StoredTensor>& tensors, const std::string& name, at::Tensor& target,
                       const std::string& source) {
  auto it = tensors.find(name);
  if (it == tensors.end()) throw InputError(source + ": model file lacks tensor '" + name + "'");
  const StoredTensor& stored = it->second;
  if (target.defined() && !target.sizes().equals(stored.shape)) {
    throw InputError(source + ": tensor '" + name + "' has shape " + shape_string(stored.shape) + ", expected " +
                     shape_string(target.sizes().vec()));
  }
  const size_t bytes = static_cast<size_t>(stored.numel()) * sizeof(float);
  at::NoGradGuard guard;
  if (target.defined() && target.is_contiguous() && target.scalar_type() == at::kFloat && target.device().is_cpu()) {
    if (bytes != 0) std::memcpy(target.data_ptr<float>(), stored.data, bytes);
  } else {
    at::Tensor copy = at::empty(stored.shape, at::kFloat);
    if (bytes != 0) std::memcpy(copy.data_ptr<float>(), stored.data, bytes);
    if (target.defined()) target.copy_(copy);
    else target = copy;
  }
  tensors.erase(it);
}

std::vector<uint8_t> serialize_nemf(const NemfModel& model) {
  auto tensors = stats_tensors(model.stats());
  for (auto& named : model.named_parameters()) tensors.push_back(named);
  return serialize_model_file(kNemfKind, model.config().to_map(), model.rig(), tensors);
}

NemfModel deserialize_nemf(const uint8_t* data, size_t size, const std::string& source) {
  ModelFileContents c = parse_model_file(data, size, source, {kNemfKind});
  NemfModel model(checked_nemf_config(c.hyperparameters, source), c.rig);
  NemfStats& s = model.stats();
  auto take = [&](const std::string& name, at::Tensor& target) { take_model_tensor(c.tensors, name, target, source); };
  take("stats.feature_mean", s.feature_mean);
  take("stats.feature_std", s.feature_std);
  take("stats.root_mean", s.root_mean);
  take("stats.root_std", s.root_std);
  take("stats.gmp_in_mean", s.gmp_in_mean);
  take("stats.gmp_in_std", s.gmp_in_std);
  take("stats.gmp_out_mean", s.gmp_out_mean);
  take("stats.gmp_out_std", s.gmp_out_std);
  for (auto& [name, param] : model.named_parameters()) take(name, param);
  check_no_extra_tensors(c.tensors, source);
  // Solvers differentiate through the network, never into it: without this every
  // forward op on a weight records an autograd node and saves its inputs.
  model.set_requires_grad(false);
  return model;
}

void save_nemf(const NemfModel& model, const std::string& path) { write_file_atomically(path, serialize_nemf(model)); }

NemfModel load_nemf(const std::string& path) {
  const FileBytes bytes = read_file_bytes(path);
  return deserialize_nemf(bytes.data(), bytes.size(), path);
}

}  // namespace mf
