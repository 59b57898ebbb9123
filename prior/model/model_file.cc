#include "prior/model/model_file.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <cstdlib>
#include <filesystem>

#include "prior/motion/errors.h"
#include "prior/util/binary_io.h"
#include "prior/util/file_writer.h"

namespace mf {

namespace {

constexpr char kMagic[8] = {'M', 'F', 'M', 'O', 'D', 'E', 'L', '\0'};

void write_tensor(ByteWriter& w, const std::string& name, const at::Tensor& t) {
  at::Tensor c = t.detach().to(at::kFloat).contiguous();
  w.str(name);
  w.u32(static_cast<uint32_t>(c.dim()));
  for (int64_t d : c.sizes()) w.pod<int64_t>(d);
  w.bytes(c.data_ptr<float>(), static_cast<size_t>(c.numel()) * sizeof(float));
}

std::vector<std::pair<std::string, at::Tensor>> stats_tensors(const NemfStats& s) {
  return {{"stats.feature_mean", s.feature_mean}, {"stats.feature_std", s.feature_std},
          {"stats.root_mean", s.root_mean},       {"stats.root_std", s.root_std},
          {"stats.gmp_in_mean", s.gmp_in_mean},   {"stats.gmp_in_std", s.gmp_in_std},
          {"stats.gmp_out_mean", s.gmp_out_mean}, {"stats.gmp_out_std", s.gmp_out_std}};
}

std::string shape_string(at::IntArrayRef s) {
  std::string out = "[";
  for (size_t i = 0; i < s.size(); ++i) out += (i ? ", " : "") + std::to_string(s[i]);
  return out + "]";
}

}  // namespace

std::vector<uint8_t> serialize_model_file(const std::string& kind, const std::map<std::string, double>& hyperparameters,
                                          const RigInfo& rig,
                                          const std::vector<std::pair<std::string, at::Tensor>>& tensors) {
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
  for (const auto& [name, t] : tensors) write_tensor(p, name, t);

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
// (one of `expected_kinds`; stored in *kind), size and checksum.
ByteReader checked_payload(const uint8_t* data, size_t size, const std::string& source,
                           const std::vector<std::string>& expected_kinds, std::string* kind) {
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
  if (stored != fnv1a64_bytes(payload, payload_size)) {
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

ModelFileContents parse_model_file(const uint8_t* data, size_t size, const std::string& source,
                                   const std::vector<std::string>& expected_kinds) {
  ModelFileContents c;
  ByteReader p = checked_payload(data, size, source, expected_kinds, &c.kind);
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

void take_model_tensor(std::map<std::string, StoredTensor>& tensors, const std::string& name, at::Tensor& target,
                       const std::string& source) {
  auto it = tensors.find(name);
  if (it == tensors.end()) throw InputError(source + ": model file lacks tensor '" + name + "'");
  const StoredTensor& stored = it->second;
  if (target.defined() && !target.sizes().equals(stored.shape)) {
    throw InputError(source + ": tensor '" + name + "' has shape " + shape_string(stored.shape) + ", expected " +
                     shape_string(target.sizes()));
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

void check_no_extra_tensors(const std::map<std::string, StoredTensor>& tensors, const std::string& source) {
  if (!tensors.empty()) {
    throw InputError(source + ": model file has unexpected tensor '" + tensors.begin()->first +
                     "' (trained with another architecture?)");
  }
}

std::vector<uint8_t> serialize_nemf(const NemfModel& model) {
  auto tensors = stats_tensors(model.stats());
  for (auto& named : model.named_parameters()) tensors.push_back(named);
  return serialize_model_file(kNemfKind, model.config().to_map(), model.rig(), tensors);
}

NemfModel deserialize_nemf(const uint8_t* data, size_t size, const std::string& source) {
  ModelFileContents c = parse_model_file(data, size, source, {kNemfKind});
  NemfConfig config = NemfConfig::from_map(c.hyperparameters);
  std::string problem = config.validate();
  if (!problem.empty()) throw InputError(source + ": invalid hyperparameters: " + problem);
  NemfModel model(config, c.rig);
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
