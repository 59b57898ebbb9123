// The model file's container: one self-describing binary file per trained
// model, read and written without libtorch (the Eigen runtime in
// prior/runtime/ reads it; the libtorch side, model_file.h, builds on it).
//
// Layout (little-endian):
//   "MFMODEL\0"                 8-byte magic
//   u32 format version          kModelFormatVersion
//   str kind                    "nemf" (kNemfKind) or an in-betweener's kind
//   u64 payload size
//   payload:
//     hyperparameters           u32 n, then n x (str name, f64 value)
//     rig                       skeleton (names, parents, offsets in metres),
//                               root forward axis, feet (joint, standing height,
//                               threshold), contact speed
//     tensors                   u32 n, then n x (str name, u32 rank, i64 dims...,
//                               float32 data): normalisation stats ("stats.*")
//                               and weights
//   u64 checksum                FNV-1a 64 of the payload
// Strings are u32 length + bytes. Loading validates every part and throws
// mf::InputError saying precisely what is wrong (not a model file, truncated,
// corrupted, wrong version, wrong kind, missing or misshapen weights).
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "prior/model/rig_info.h"
#include "prior/motion/errors.h"
#include "prior/util/binary_io.h"

namespace mf {

constexpr uint32_t kModelFormatVersion = 1;

/// A tensor as a model file stores it: its shape and its float32 values,
/// which stay in the file's bytes (no copy; not necessarily aligned), so
/// they are valid only while the bytes given to parse_model_file live.
struct StoredTensor {
  std::vector<int64_t> shape;
  const uint8_t* data = nullptr;
  int64_t numel() const;
};

/// A tensor to write: its name, shape and contiguous float32 values (row-major,
/// shape's product of them), which must live until serialize_model_container
/// returns.
struct TensorToWrite {
  std::string name;
  std::vector<int64_t> shape;
  const float* data = nullptr;
};

/// The generic container, shared by every model kind (the NeMF prior, the
/// in-betweeners in prior/inbetween/inbetweener.cc).
struct ModelFileContents {
  std::string kind;
  std::map<std::string, double> hyperparameters;
  RigInfo rig;                                   ///< skeleton validated
  std::map<std::string, StoredTensor> tensors;   ///< finite values; views of the parsed bytes
};

/// The bytes of a model file of `kind` (layout above); tensors are written in
/// the given order.
std::vector<uint8_t> serialize_model_container(const std::string& kind,
                                               const std::map<std::string, double>& hyperparameters,
                                               const RigInfo& rig, const std::vector<TensorToWrite>& tensors);
/// The payload's checksum computed on a thread of its own while the caller
/// parses and builds (FNV-1a goes a byte at a time: most of the time of a
/// load), giving back the pages of `file` it has passed (FileBytes::release).
/// verify() waits for it and throws "corrupted model file (checksum
/// mismatch)"; the destructor waits. Without a thread it computes inline.
class ConcurrentChecksum {
 public:
  explicit ConcurrentChecksum(const FileBytes* file) : file_(file) {}
  ~ConcurrentChecksum();
  ConcurrentChecksum(const ConcurrentChecksum&) = delete;
  ConcurrentChecksum& operator=(const ConcurrentChecksum&) = delete;
  /// Starts hashing [payload, payload + n) against `stored` (parse_model_file calls it).
  void start(const uint8_t* payload, size_t n, uint64_t stored, const std::string& source);
  /// Nothing to do when start() was never called (the header was refused).
  void verify();

 private:
  void join();
  const FileBytes* file_;
  std::thread thread_;
  uint64_t stored_ = 0, computed_ = 0;
  bool started_ = false;
  std::string source_;
};

/// Parses and validates a model file (magic, version, size, checksum, rig,
/// tensors). `expected_kinds` (non-empty) lists the kinds the caller accepts;
/// any other throws "wrong kind of model". `source` names the file in errors.
/// With `checksum`, the checksum is left to it (ConcurrentChecksum): the
/// caller must verify() it before trusting what it built; read_model_file
/// does so.
ModelFileContents parse_model_file(const uint8_t* data, size_t size, const std::string& source,
                                   const std::vector<std::string>& expected_kinds,
                                   ConcurrentChecksum* checksum = nullptr);

/// build(contents) on a model file parsed while its checksum is computed on
/// another thread (`file`, if any, the file the bytes are mapped from). The
/// checksum is verified before the result is returned and before any
/// exception of the parse or of build propagates, so a corrupted file says
/// so, as parse_model_file does.
template <class Build>
auto read_model_file(const uint8_t* data, size_t size, const std::string& source,
                     const std::vector<std::string>& expected_kinds, const FileBytes* file, Build&& build) {
  ConcurrentChecksum checksum(file);
  try {
    ModelFileContents contents = parse_model_file(data, size, source, expected_kinds, &checksum);
    auto built = build(contents);
    checksum.verify();
    return built;
  } catch (...) {
    checksum.verify();  // a corrupted file's error replaces what its bytes made the parse or build throw
    throw;
  }
}
/// Throws InputError naming the first tensor left in `tensors` (one the
/// architecture does not have), if any.
void check_no_extra_tensors(const std::map<std::string, StoredTensor>& tensors, const std::string& source);
/// "[2, 3]": a shape for error messages.
std::string shape_string(const std::vector<int64_t>& shape);

/// The default model shipped in models/: MF_MODEL if set, else the installed or
/// source-tree models/motionfield-prior.mfm, else "" when none exists.
std::string default_model_path();

}  // namespace mf
