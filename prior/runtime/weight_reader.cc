#include "prior/runtime/weight_reader.h"

#include <cstring>
#include <utility>

#include "prior/motion/errors.h"

namespace mf::runtime {

WeightReader::WeightReader(std::map<std::string, StoredTensor>* tensors, std::string source, const FileBytes* file)
    : tensors_(tensors), source_(std::move(source)), file_(file) {}

std::vector<float> WeightReader::take(const std::string& name, const std::vector<int64_t>& shape) {
  auto it = tensors_->find(name);
  if (it == tensors_->end()) throw InputError(source_ + ": model file lacks tensor '" + name + "'");
  if (it->second.shape != shape) {
    throw InputError(source_ + ": tensor '" + name + "' has shape " + shape_string(it->second.shape) +
                     ", expected " + shape_string(shape));
  }
  std::vector<float> values(static_cast<size_t>(it->second.numel()));
  if (!values.empty()) std::memcpy(values.data(), it->second.data, values.size() * sizeof(float));
  if (file_) file_->release(it->second.data, values.size() * sizeof(float));
  tensors_->erase(it);
  return values;
}

MatrixRXf WeightReader::matrix(const std::string& name, int64_t rows, int64_t cols) {
  const std::vector<float> v = take(name, {rows, cols});
  return Eigen::Map<const MatrixRXf>(v.data(), rows, cols);
}

RowVectorXf WeightReader::vector(const std::string& name, int64_t n) {
  const std::vector<float> v = take(name, {n});
  return Eigen::Map<const RowVectorXf>(v.data(), n);
}

Conv1dWeights WeightReader::conv(const std::string& prefix, int64_t out, int64_t in, int64_t kernel, bool bias) {
  const std::vector<float> w = take(prefix + ".weight", {out, in, kernel});
  std::vector<MatrixRXf> taps(kernel, MatrixRXf(in, out));
  for (int64_t o = 0; o < out; ++o)
    for (int64_t i = 0; i < in; ++i)
      for (int64_t k = 0; k < kernel; ++k) taps[k](i, o) = w[(o * in + i) * kernel + k];
  Conv1dWeights c;
  for (MatrixRXf& tap : taps) c.taps.emplace_back(std::move(tap));
  c.bias = bias ? vector(prefix + ".bias", out) : RowVectorXf::Zero(out);
  return c;
}

Conv1dWeights WeightReader::linear(const std::string& prefix, int64_t out, int64_t in) {
  Conv1dWeights c;
  c.taps.emplace_back(MatrixRXf(matrix(prefix + ".weight", out, in).transpose()));
  c.bias = vector(prefix + ".bias", out);
  return c;
}

void WeightReader::finish() const { check_no_extra_tensors(*tensors_, source_); }

}  // namespace mf::runtime
