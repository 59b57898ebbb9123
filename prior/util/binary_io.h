// Little-endian binary serialisation with bounds checks, for the model file and
// the data cache. A reader never reads past its buffer: a short buffer throws
// mf::InputError("<what>: truncated ...").
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "prior/motion/errors.h"

namespace mf {

class ByteWriter {
 public:
  void bytes(const void* data, size_t n) {
    const auto* p = static_cast<const uint8_t*>(data);
    buffer_.insert(buffer_.end(), p, p + n);
  }
  template <class T>
  void pod(const T& v) {
    bytes(&v, sizeof(T));
  }
  void u32(uint32_t v) { pod(v); }
  void i32(int32_t v) { pod(v); }
  void u64(uint64_t v) { pod(v); }
  void f64(double v) { pod(v); }
  void str(const std::string& s) {
    u32(static_cast<uint32_t>(s.size()));
    bytes(s.data(), s.size());
  }
  const std::vector<uint8_t>& buffer() const { return buffer_; }
  std::vector<uint8_t>& buffer() { return buffer_; }

 private:
  std::vector<uint8_t> buffer_;
};

class ByteReader {
 public:
  ByteReader(const uint8_t* data, size_t size, std::string what) : data_(data), size_(size), what_(std::move(what)) {}
  void bytes(void* out, size_t n) {
    need(n);
    // An empty tensor's data pointer may be null, and memcpy's may never be
    // (UBSan nonnull-attribute; found by fuzz_model_file).
    if (n != 0) std::memcpy(out, data_ + pos_, n);
    pos_ += n;
  }
  template <class T>
  T pod() {
    T v;
    bytes(&v, sizeof(T));
    return v;
  }
  uint32_t u32() { return pod<uint32_t>(); }
  int32_t i32() { return pod<int32_t>(); }
  uint64_t u64() { return pod<uint64_t>(); }
  double f64() { return pod<double>(); }
  /// A string of at most `max_length` bytes.
  std::string str(size_t max_length = 1 << 20) {
    uint32_t n = u32();
    if (n > max_length) fail("string length " + std::to_string(n) + " exceeds " + std::to_string(max_length));
    need(n);
    std::string s(reinterpret_cast<const char*>(data_ + pos_), n);
    pos_ += n;
    return s;
  }
  /// The next `n` bytes, in place (no copy); the reader moves past them.
  const uint8_t* skip(size_t n) {
    need(n);
    const uint8_t* at = data_ + pos_;
    pos_ += n;
    return at;
  }
  /// Checks that `count` items of `item_size` bytes can still be read.
  void need_items(uint64_t count, size_t item_size) {
    if (item_size != 0 && count > (size_ - pos_) / item_size) fail("truncated (count " + std::to_string(count) + ")");
  }
  size_t position() const { return pos_; }
  size_t remaining() const { return size_ - pos_; }
  [[noreturn]] void fail(const std::string& message) const {
    throw InputError(what_ + ": " + message + " at byte " + std::to_string(pos_));
  }

 private:
  void need(size_t n) {
    if (n > size_ - pos_) fail("truncated (needs " + std::to_string(n) + " more bytes, has " +
                               std::to_string(size_ - pos_) + ")");
  }
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
  std::string what_;
};

/// FNV-1a 64-bit hash (offset basis 0xcbf29ce484222325, prime 0x100000001b3)
/// of a byte range: the project's one hash (model file checksums, dataset
/// split and cache keys).
inline uint64_t fnv1a64_bytes(const uint8_t* data, size_t n, uint64_t h = 0xcbf29ce484222325ULL) {
  for (size_t i = 0; i < n; ++i) {
    h ^= data[i];
    h *= 0x100000001b3ULL;
  }
  return h;
}
/// FNV-1a 64-bit hash of the bytes of `s`.
inline uint64_t fnv1a64(const std::string& s) {
  return fnv1a64_bytes(reinterpret_cast<const uint8_t*>(s.data()), s.size());
}

/// A file that cannot be opened, read or written (the C API's MF_ERROR_IO);
/// the message names the file and the reason (strerror).
class FileError : public InputError {
 public:
  explicit FileError(const std::string& message) : InputError(message) {}
};

/// The size limits of input files (docs/RELIABILITY.md, "Bad input and
/// faults"): a file is checked against its limit before it is read (regular
/// files by their size, pipes while reading).
constexpr size_t kMiB = size_t{1} << 20;
constexpr size_t kMaxBvhFileBytes = 512 * kMiB;    ///< BVH: an hour at 120 fps on a 70-joint rig
constexpr size_t kMaxModelFileBytes = 2048 * kMiB; ///< model files (.mfm)
constexpr size_t kMaxTextFileBytes = 64 * kMiB;    ///< path CSVs, rig anatomy
constexpr size_t kMaxRigMapFileBytes = 1 * kMiB;   ///< rig map files
constexpr size_t kMaxConstraintsFileBytes = 16 * kMiB;  ///< constraints files (mf_constraints_load_json)

/// Reads a whole file of at most `max_bytes`. Throws FileError
/// "cannot read the <what> <path>: <reason>" when it cannot be opened or read,
/// is a directory or a device (/dev/zero, a terminal: not a file), or is
/// larger than `max_bytes`. Regular files, pipes and FIFOs are read.
std::string read_file_limited(const std::string& path, const std::string& what, size_t max_bytes);

/// The read-only bytes of a whole file (read_file_bytes). A regular file is
/// mapped into memory, not copied: the first touch of fresh memory costs a
/// page fault per 4 KiB, and on virtual machines these dominated loading a
/// model (a 22 MB copy took 150-300 ms; docs/BENCHMARKS.md, "Start-up").
/// Pipes and files that cannot be mapped are read into memory instead.
/// A mapped file must not be truncated while the object lives (the process
/// would get SIGBUS); motionfield itself only ever replaces files by rename
/// (prior/util/file_writer.h),
/// which leaves a mapped file intact.
class FileBytes {
 public:
  FileBytes() = default;
  ~FileBytes();
  FileBytes(FileBytes&& other) noexcept;
  FileBytes& operator=(FileBytes&& other) noexcept;
  FileBytes(const FileBytes&) = delete;
  FileBytes& operator=(const FileBytes&) = delete;

  const uint8_t* data() const;
  size_t size() const;
  /// Gives back the memory of the whole pages within [begin, begin + n),
  /// bytes of this file the caller has copied and will not read again: a
  /// mapped file's pages leave the process (touched again, they are read back
  /// from the file), so a loader that copies a large file piece by piece does
  /// not hold it twice. No effect on bytes read into memory or outside the file.
  void release(const uint8_t* begin, size_t n) const;

 private:
  friend FileBytes read_file_bytes(const std::string& path);
  void* map_ = nullptr;  ///< the mapping, or null when the bytes are in text_
  size_t map_size_ = 0;
  std::string text_;
};

/// Reads a whole model-sized file (the checks and errors of
/// read_file_limited, kMaxModelFileBytes).
FileBytes read_file_bytes(const std::string& path);

// The one file writer (write_file_atomically, OutputFiles) is prior/util/file_writer.h.

}  // namespace mf
