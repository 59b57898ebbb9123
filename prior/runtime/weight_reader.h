// Weights for the Eigen runtime, taken out of a parsed model file
// (prior/model/model_container.h) by name, with their shapes checked against
// the architecture the hyperparameters describe.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "prior/model/model_container.h"
#include "prior/runtime/tensor_ops.h"
#include "prior/util/binary_io.h"

namespace mf::runtime {

/// Takes tensors out of a model file's map: each call copies one tensor (a
/// float32 copy out of the file's bytes) and removes it from the map; a
/// missing or misshapen tensor throws InputError naming it and `source`.
/// finish() throws when a tensor is left over (another architecture), so a
/// reader that took every weight the architecture has proves the file has
/// no others. With the `file` the tensors view, each tensor's pages are
/// released once copied (FileBytes::release), so that a load does not hold the
/// weights twice.
class WeightReader {
 public:
  WeightReader(std::map<std::string, StoredTensor>* tensors, std::string source, const FileBytes* file = nullptr);

  /// A [rows, cols] tensor as it is stored (libtorch's Linear: [out, in]).
  MatrixRXf matrix(const std::string& name, int64_t rows, int64_t cols);
  /// A [n] tensor as a row vector.
  RowVectorXf vector(const std::string& name, int64_t n);
  /// `prefix`.weight [out, in, kernel] as per-tap matrices and `prefix`.bias
  /// [out] (zeros when `bias` is false, where the convolution has none).
  Conv1dWeights conv(const std::string& prefix, int64_t out, int64_t in, int64_t kernel, bool bias = true);
  /// A Linear layer `prefix`.weight [out, in] and `prefix`.bias [out] as a
  /// kernel-1 convolution (taps[0] = weight^T [in, out]): rows of [T, in] in.
  Conv1dWeights linear(const std::string& prefix, int64_t out, int64_t in);
  /// Throws InputError naming the first tensor not taken, if any.
  void finish() const;

 private:
  std::vector<float> take(const std::string& name, const std::vector<int64_t>& shape);
  std::map<std::string, StoredTensor>* tensors_;
  std::string source_;
  const FileBytes* file_;
};

}  // namespace mf::runtime
