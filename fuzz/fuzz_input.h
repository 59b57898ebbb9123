// A small reader of fuzz input bytes for the structured targets (the C API
// ones): integers in a range, floats, strings. Past the end of the input every
// read returns zeros, so every input is a valid (if short) recipe. Used
// instead of clang's FuzzedDataProvider so that the targets also build with
// g++ (the replay driver, replay_main.cc).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

namespace mf::fuzz {

class FuzzInput {
 public:
  FuzzInput(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  size_t remaining() const { return size_ - pos_; }

  /// `n` bytes into `out` (zeros past the end).
  void bytes(void* out, size_t n) {
    const size_t k = n < remaining() ? n : remaining();
    if (k) std::memcpy(out, data_ + pos_, k);
    if (k < n) std::memset(static_cast<uint8_t*>(out) + k, 0, n - k);
    pos_ += k;
  }
  uint8_t u8() {
    uint8_t v;
    bytes(&v, 1);
    return v;
  }
  uint32_t u32() {
    uint32_t v;
    bytes(&v, sizeof v);
    return v;
  }
  /// An integer in [lo, hi] (one byte when the range fits in one).
  int64_t range(int64_t lo, int64_t hi) {
    const uint64_t span = static_cast<uint64_t>(hi - lo) + 1;
    uint64_t v = span <= 256 ? u8() : u32();
    return lo + static_cast<int64_t>(span ? v % span : v);
  }
  bool flag() { return u8() & 1; }
  /// Any float bit pattern, including NaN and infinities.
  float any_float() {
    float v;
    bytes(&v, sizeof v);
    return v;
  }
  double any_double() {
    double v;
    bytes(&v, sizeof v);
    return v;
  }
  /// A float that is mostly plausible: small values in [-2, 2] from one byte
  /// (selector < 240), else any bit pattern.
  float plausible_float() {
    const uint8_t selector = u8();
    if (selector < 240) return (static_cast<int>(u8()) - 128) / 64.0f;
    return any_float();
  }
  /// A string of up to `max` bytes (length byte, then the bytes).
  std::string string(size_t max) {
    size_t n = u8();
    if (n > max) n = max;
    if (n > remaining()) n = remaining();
    std::string s(reinterpret_cast<const char*>(data_ + pos_), n);
    pos_ += n;
    return s;
  }
  /// Every byte left.
  std::string rest() {
    std::string s(reinterpret_cast<const char*>(data_ + pos_), remaining());
    pos_ = size_;
    return s;
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
};

}  // namespace mf::fuzz
