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

/// FNV-1a 64-bit hash of a byte range.
inline uint64_t fnv1a64_bytes(const uint8_t* data, size_t n, uint64_t h = 0xcbf29ce484222325ULL) {
  for (size_t i = 0; i < n; ++i) {
    h ^= data[i];
    h *= 0x100000001b3ULL;
  }
  return h;
}

/// Reads a whole file; throws InputError naming the path if it cannot.
std::vector<uint8_t> read_file_bytes(const std::string& path);
/// Writes through a temporary file and a rename; throws std::runtime_error on failure.
void write_file_atomically(const std::string& path, const std::vector<uint8_t>& bytes);

}  // namespace mf
