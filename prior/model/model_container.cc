#include "prior/model/model_container.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <utility>

#include "prior/motion/errors.h"
#include "prior/util/binary_io.h"

namespace mf {

namespace {

constexpr char kMagic[8] = {'M', 'F', 'M', 'O', 'D', 'E', 'L', '\0'};

void write_tensor(ByteWriter& w, const TensorToWrite& t) {
  int64_t numel = 1;
  for (int64_t d : t.shape) numel *= d;
  w.str(t.name);
  w.u32(static_cast<uint32_t>(t.shape.size()));
  for (int64_t d : t.shape) w.pod<int64_t>(d);
  w.bytes(t.data, static_cast<size_t>(numel) * sizeof(float));
}

}  // namespace

std::vector<uint8_t> serialize_model_container(const std::string& kind,
                                               const std::map<std::string, double>& hyperparameters,
                                               const RigInfo& rig, const std::vector<TensorToWrite>& tensors) {
  ByteWriter p;
  p.u32(static_cast<uint32_t>(hyperparameters.size()));
  for (const auto& [k, v] : hyperparameters) {
    p.str(k);
    p.f64(v);
  }
  const Skeleton& sk = rig.skeleton;
  p.u32(static_cast<uint32_t>(sk.num_joints()));
  for (int j = 0; j < sk.num_joints(); ++j) {
    p.str(sk.names[j]);
    p.i32(sk.parents[j]);
    for (int a = 0; a < 3; ++a) p.f64(sk.offsets[j][a]);
  }
  for (int a = 0; a < 3; ++a) p.f64(rig.root_forward[a]);
  p.u32(static_cast<uint32_t>(rig.num_feet()));
  for (int k = 0; k < rig.num_feet(); ++k) {
    p.i32(rig.foot_joints[k]);
    p.f64(rig.foot_heights[k]);
    p.f64(rig.foot_thresholds[k]);
  }
  p.f64(rig.contact_speed);
  p.u32(static_cast<uint32_t>(tensors.size()));
  for (const TensorToWrite& t : tensors) write_tensor(p, t);

  ByteWriter out;
  out.bytes(kMagic, sizeof(kMagic));
  out.u32(kModelFormatVersion);
  out.str(kind);
  out.u64(p.buffer().size());
  out.bytes(p.buffer().data(), p.buffer().size());
  out.u64(fnv1a64_bytes(p.buffer().data(), p.buffer().size()));
  return std::move(out.buffer());
}
namespace {

// The payload of a model file after checking its magic, format version, kind
// (one of `expected_kinds`; stored in *kind), size and checksum (left to
// `checksum` when given).
ByteReader checked_payload(const uint8_t* data, size_t size, const std::string& source,
                           const std::vector<std::string>& expected_kinds, std::string* kind,
                           ConcurrentChecksum* checksum) {
  ByteReader head(data, size, source);
  char magic[8];
  if (size < sizeof(magic) || std::memcmp(data, kMagic, sizeof(magic)) != 0) {
    throw InputError(source + ": not a motionfield model file (bad magic)");
  }
  head.bytes(magic, sizeof(magic));
  uint32_t version = head.u32();
  if (version != kModelFormatVersion) {
    throw InputError(source + ": unsupported model format version " + std::to_string(version) +
                     " (this build reads version " + std::to_string(kModelFormatVersion) + ")");
  }
  *kind = head.str(64);
  if (std::find(expected_kinds.begin(), expected_kinds.end(), *kind) == expected_kinds.end()) {
    std::string expected;
    for (size_t i = 0; i < expected_kinds.size(); ++i) {
      expected += (i ? (i + 1 == expected_kinds.size() ? "' or '" : "', '") : "") + expected_kinds[i];
    }
    throw InputError(source + ": wrong kind of model: the file holds a '" + *kind + "' model, expected '" + expected +
                     "'");
  }
  uint64_t payload_size = head.u64();
  if (payload_size > head.remaining() || head.remaining() - payload_size < sizeof(uint64_t)) {
    throw InputError(source + ": truncated model file (payload of " + std::to_string(payload_size) +
                     " bytes announced, " + std::to_string(head.remaining()) + " bytes left)");
  }
  const uint8_t* payload = data + head.position();
  uint64_t stored;
  std::memcpy(&stored, payload + payload_size, sizeof(stored));
  if (checksum) {
    checksum->start(payload, payload_size, stored, source);
  } else if (stored != fnv1a64_bytes(payload, payload_size)) {
    throw InputError(source + ": corrupted model file (checksum mismatch)");
  }
  return ByteReader(payload, payload_size, source);
}

// The rig as serialize_model_file() writes it.
RigInfo read_rig(ByteReader& p, const std::string& source) {
  RigInfo rig;
  uint32_t J = p.u32();
  if (J == 0 || J > 1024) p.fail("bad joint count " + std::to_string(J));
  for (uint32_t j = 0; j < J; ++j) {
    rig.skeleton.names.push_back(p.str(1024));
    rig.skeleton.parents.push_back(p.i32());
    Eigen::Vector3d o;
    for (int a = 0; a < 3; ++a) o[a] = p.f64();
    rig.skeleton.offsets.push_back(o);
  }
  try {
    rig.skeleton.validate();
  } catch (const InputError& e) {
    throw InputError(source + ": invalid skeleton: " + e.what());
  }
  for (int a = 0; a < 3; ++a) rig.root_forward[a] = p.f64();
  uint32_t F = p.u32();
  if (F > J) p.fail("more feet than joints");
  for (uint32_t k = 0; k < F; ++k) {
    int joint = p.i32();
    if (joint < 0 || joint >= static_cast<int>(J)) p.fail("foot joint out of range");
    rig.foot_joints.push_back(joint);
    rig.foot_heights.push_back(p.f64());
    rig.foot_thresholds.push_back(p.f64());
  }
  rig.contact_speed = p.f64();
  return rig;
}

// The named tensors as write_tensor() writes them, as views of the bytes;
// finite values only.
std::map<std::string, StoredTensor> read_tensors(ByteReader& p) {
  std::map<std::string, StoredTensor> tensors;
  uint32_t count = p.u32();
  if (count > 100000) p.fail("too many tensors");
  for (uint32_t i = 0; i < count; ++i) {
    std::string name = p.str(1024);
    uint32_t rank = p.u32();
    if (rank > 8) p.fail("tensor '" + name + "' has rank " + std::to_string(rank));
    StoredTensor t;
    t.shape.resize(rank);
    uint64_t numel = 1;
    for (auto& d : t.shape) {
      d = p.pod<int64_t>();
      if (d < 0 || d > (int64_t(1) << 32)) p.fail("tensor '" + name + "' has a bad dimension");
      // Dimensions of 2^32 wrap the product to 0, which need_items() accepts
      // and at::empty() refuses with a c10::Error (found by fuzz_model_file).
      if (__builtin_mul_overflow(numel, static_cast<uint64_t>(d), &numel))
        p.fail("tensor '" + name + "' has too many elements");
    }
    p.need_items(numel, sizeof(float));
    t.data = p.skip(numel * sizeof(float));
    for (uint64_t k = 0; k < numel; ++k) {
      float v;
      std::memcpy(&v, t.data + k * sizeof(float), sizeof v);
      if (!std::isfinite(v)) p.fail("tensor '" + name + "' holds non-finite values");
    }
    tensors[name] = std::move(t);
  }
  return tensors;
}

}  // namespace

ConcurrentChecksum::~ConcurrentChecksum() { join(); }

void ConcurrentChecksum::start(const uint8_t* payload, size_t n, uint64_t stored, const std::string& source) {
  stored_ = stored;
  source_ = source;
  started_ = true;
  auto hash = [this, payload, n] {
    constexpr size_t kChunk = size_t{1} << 20;
    uint64_t h = fnv1a64_bytes(payload, 0);  // FNV-1a's offset basis, continued chunk by chunk
    for (size_t at = 0; at < n; at += kChunk) {
      const size_t len = std::min(kChunk, n - at);
      h = fnv1a64_bytes(payload + at, len, h);
      if (file_) file_->release(payload + at, len);
    }
    computed_ = h;
  };
  try {
    thread_ = std::thread(hash);
  } catch (const std::system_error&) {
    hash();  // no thread to be had: inline
  }
}

void ConcurrentChecksum::join() {
  if (thread_.joinable()) thread_.join();
}

void ConcurrentChecksum::verify() {
  join();
  if (started_ && computed_ != stored_) throw InputError(source_ + ": corrupted model file (checksum mismatch)");
}

ModelFileContents parse_model_file(const uint8_t* data, size_t size, const std::string& source,
                                   const std::vector<std::string>& expected_kinds, ConcurrentChecksum* checksum) {
  ModelFileContents c;
  ByteReader p = checked_payload(data, size, source, expected_kinds, &c.kind, checksum);
  uint32_t n = p.u32();
  if (n > 1000) p.fail("too many hyperparameters");
  for (uint32_t i = 0; i < n; ++i) {
    std::string k = p.str(256);
    c.hyperparameters[k] = p.f64();
  }
  c.rig = read_rig(p, source);
  c.tensors = read_tensors(p);
  if (p.remaining() != 0) p.fail("unexpected trailing data");
  return c;
}

int64_t StoredTensor::numel() const {
  int64_t n = 1;
  for (int64_t d : shape) n *= d;
  return n;
}

void check_no_extra_tensors(const std::map<std::string, StoredTensor>& tensors, const std::string& source) {
  if (!tensors.empty()) {
    throw InputError(source + ": model file has unexpected tensor '" + tensors.begin()->first +
                     "' (trained with another architecture?)");
  }
}

std::string shape_string(const std::vector<int64_t>& shape) {
  std::string out = "[";
  for (size_t i = 0; i < shape.size(); ++i) out += (i ? ", " : "") + std::to_string(shape[i]);
  return out + "]";
}

std::string default_model_path() {
  namespace fs = std::filesystem;
  if (const char* env = std::getenv("MF_MODEL"); env && *env) return env;
#ifdef MF_INSTALLED_MODEL
  if (fs::exists(MF_INSTALLED_MODEL)) return MF_INSTALLED_MODEL;
#endif
#ifdef MF_SOURCE_MODEL
  if (fs::exists(MF_SOURCE_MODEL)) return MF_SOURCE_MODEL;
#endif
  return "";
}

}  // namespace mf
