#include "training/data_parallel.h"

// ProcessGroupGloo.hpp declares its classes only with USE_C10D_GLOO (as
// libtorch itself was built); the gloo headers come from libgloo-dev.
#ifndef USE_C10D_GLOO
#define USE_C10D_GLOO 1
#endif
#include <ATen/ATen.h>
#include <torch/csrc/distributed/c10d/ProcessGroupGloo.hpp>
#include <torch/csrc/distributed/c10d/TCPStore.hpp>

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "prior/motion/errors.h"

namespace mf {

namespace {

// An integer environment variable, or `fallback` when unset.
int env_int(const char* name, int fallback) {
  const char* v = std::getenv(name);
  if (v == nullptr || *v == '\0') return fallback;
  char* end = nullptr;
  const long x = std::strtol(v, &end, 10);
  if (*end != '\0' || x < 0 || x > 1000000) {
    throw InputError(std::string("the environment variable ") + name + " is not a valid number: '" + v + "'");
  }
  return static_cast<int>(x);
}

bool is_loopback(const std::string& host) { return host == "localhost" || host.rfind("127.", 0) == 0 || host == "::1"; }

}  // namespace

DistributedOptions DistributedOptions::from_environment() {
  DistributedOptions o;
  o.world_size = env_int("WORLD_SIZE", o.world_size);
  o.rank = env_int("RANK", o.rank);
  if (const char* addr = std::getenv("MASTER_ADDR"); addr != nullptr && *addr != '\0') o.master_addr = addr;
  o.master_port = env_int("MASTER_PORT", o.master_port);
  return o;
}

void DistributedOptions::set_master(const std::string& address) {
  const size_t colon = address.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == address.size()) {
    throw InputError("--master: expected ADDR:PORT, got '" + address + "'");
  }
  const std::string port = address.substr(colon + 1);
  if (port.find_first_not_of("0123456789") != std::string::npos || port.size() > 5) {
    throw InputError("--master: not a port number: '" + port + "'");
  }
  master_addr = address.substr(0, colon);
  if (master_addr.size() > 2 && master_addr.front() == '[' && master_addr.back() == ']') {
    master_addr = master_addr.substr(1, master_addr.size() - 2);  // [IPv6]:PORT
  }
  master_port = std::stoi(port);
}

std::string DistributedOptions::validate() const {
  if (world_size < 1) return "--world-size must be at least 1";
  if (rank < 0 || rank >= world_size) {
    return "--rank must be in [0, " + std::to_string(world_size - 1) + "] with --world-size " +
           std::to_string(world_size) + " (got " + std::to_string(rank) + ")";
  }
  if (world_size > 1 && (master_port < 1 || master_port > 65535)) return "--master: the port must be in [1, 65535]";
  if (world_size > 1 && master_addr.empty()) return "--master: the address is empty";
  if (!(timeout_seconds > 0)) return "--dist-timeout must be positive";
  return "";
}

namespace training {

struct DataParallel::Group {
  c10::intrusive_ptr<c10d::Store> store;
  c10::intrusive_ptr<c10d::ProcessGroupGloo> pg;
};

namespace {

// The network device: loopback for a master on this host, else the interface
// named by GLOO_SOCKET_IFNAME (as torch.distributed), else the address of this
// host's name.
std::shared_ptr<::gloo::transport::Device> gloo_device(const std::string& master_addr) {
  if (is_loopback(master_addr)) return c10d::ProcessGroupGloo::createDeviceForHostname("127.0.0.1");
  if (const char* ifname = std::getenv("GLOO_SOCKET_IFNAME"); ifname != nullptr && *ifname != '\0') {
    return c10d::ProcessGroupGloo::createDeviceForInterface(ifname);
  }
  return c10d::ProcessGroupGloo::createDefaultDevice();
}

// The message of `e` without the C++ backtrace that c10::Error appends.
std::string reason(const std::exception& e) {
  if (const auto* c10_error = dynamic_cast<const c10::Error*>(&e)) return c10_error->what_without_backtrace();
  return e.what();
}

std::chrono::milliseconds to_ms(double seconds) {
  return std::chrono::milliseconds(static_cast<int64_t>(seconds * 1000.0));
}

}  // namespace

DataParallel::DataParallel(const DistributedOptions& options) : options_(options) {
  const std::string problem = options.validate();
  if (!problem.empty()) throw InputError("train: " + problem);
  if (!distributed()) return;
  const std::string where = options.master_addr + ":" + std::to_string(options.master_port);
  try {
    c10d::TCPStoreOptions so;
    so.port = static_cast<uint16_t>(options.master_port);
    so.isServer = options.rank == 0;
    so.numWorkers = static_cast<size_t>(options.world_size);
    so.timeout = to_ms(options.timeout_seconds);
    group_ = std::make_unique<Group>();
    group_->store = c10::make_intrusive<c10d::TCPStore>(options.master_addr, so);
    auto po = c10d::ProcessGroupGloo::Options::create(to_ms(options.timeout_seconds));
    po->devices.push_back(gloo_device(options.master_addr));
    group_->pg = c10::make_intrusive<c10d::ProcessGroupGloo>(group_->store, options.rank, options.world_size, po);
  } catch (const std::exception& e) {
    throw DistributedError("distributed training: " + describe() + " could not form the group of " +
                           std::to_string(options.world_size) + " processes at " + where + " within " +
                           std::to_string(static_cast<int>(options.timeout_seconds)) +
                           " s (is every rank started with the same --master and --world-size?): " + reason(e));
  }
}

DataParallel::~DataParallel() {
  if (!scratch_.empty()) {
    std::error_code ignored;
    std::filesystem::remove_all(scratch_, ignored);
  }
}

std::string DataParallel::describe() const {
  return distributed() ? "rank " + std::to_string(rank()) + " of " + std::to_string(world_size()) : std::string();
}

std::pair<size_t, size_t> DataParallel::shard(size_t begin, size_t end) const {
  const size_t n = end - begin, r = static_cast<size_t>(rank()), w = static_cast<size_t>(world_size());
  return {begin + n * r / w, begin + n * (r + 1) / w};
}

// One collective on `tensors` (sum all-reduce, or broadcast from rank 0); a
// failure or timeout becomes a DistributedError naming `what`.
at::Tensor DataParallel::run(const char* what, std::vector<at::Tensor> tensors, bool broadcast) {
  try {
    c10::intrusive_ptr<c10d::Work> work;
    if (broadcast) {
      work = group_->pg->broadcast(tensors, c10d::BroadcastOptions{});
    } else {
      work = group_->pg->allreduce(tensors, c10d::AllreduceOptions{});
    }
    work->wait(to_ms(options_.timeout_seconds));
  } catch (const std::exception& e) {
    throw DistributedError("distributed training: " + describe() + ": " + what +
                           " failed: another process of the group died, hung for more than " +
                           std::to_string(static_cast<int>(options_.timeout_seconds)) +
                           " s (--dist-timeout) or is unreachable: " + reason(e));
  }
  return tensors.front();
}

void DataParallel::broadcast(const std::vector<at::Tensor>& tensors) {
  if (!distributed() || tensors.empty()) return;
  at::NoGradGuard no_grad;
  std::vector<at::Tensor> flat;
  for (const at::Tensor& t : tensors) flat.push_back(t.detach().reshape({-1}).to(at::kFloat));
  at::Tensor all = run("broadcasting rank 0's parameters", {at::cat(flat)}, true);
  int64_t at = 0;
  for (const at::Tensor& t : tensors) {
    const int64_t n = t.numel();
    t.detach().copy_(all.narrow(0, at, n).view(t.sizes()));
    at += n;
  }
}

void DataParallel::average_gradients(const std::vector<at::Tensor>& parameters, double local_weight) {
  if (!distributed()) return;
  at::NoGradGuard no_grad;
  // One buffer, kept between steps (Gloo over TCP is several times slower on
  // freshly allocated memory): every gradient times the local weight, then the weight.
  int64_t size = 1;
  for (const at::Tensor& p : parameters) size += p.numel();
  if (!gradient_buffer_.defined() || gradient_buffer_.numel() != size) gradient_buffer_ = at::empty({size}, at::kFloat);
  int64_t at = 0;
  for (const at::Tensor& p : parameters) {
    at::Tensor part = gradient_buffer_.narrow(0, at, p.numel());
    if (p.grad().defined()) part.copy_(p.grad().reshape({-1})).mul_(local_weight);
    else part.zero_();
    at += p.numel();
  }
  gradient_buffer_.narrow(0, at, 1).fill_(local_weight);
  run("averaging the gradients", {gradient_buffer_}, false);
  const double total = gradient_buffer_[at].item<double>();
  if (!(total > 0)) throw std::runtime_error("average_gradients: the global batch is empty");
  at = 0;
  for (const at::Tensor& p : parameters) {
    const int64_t n = p.numel();
    if (!p.grad().defined()) p.mutable_grad() = at::zeros_like(p);
    p.mutable_grad().copy_(gradient_buffer_.narrow(0, at, n).view(p.sizes())).div_(total);
    at += n;
  }
}

std::vector<double> DataParallel::sum(const std::vector<double>& values) {
  if (!distributed() || values.empty()) return values;
  at::Tensor t = at::tensor(values, at::kDouble);
  t = run("summing the losses", {t}, false);
  return std::vector<double>(t.data_ptr<double>(), t.data_ptr<double>() + t.numel());
}

std::vector<double> DataParallel::agree(const std::vector<double>& values) {
  if (!distributed() || values.empty()) return values;
  at::Tensor t = at::tensor(values, at::kDouble);
  t = run("agreeing on rank 0's clock", {t}, true);
  return std::vector<double>(t.data_ptr<double>(), t.data_ptr<double>() + t.numel());
}

// Rank 0's `bytes` on every rank: the size, then the bytes.
std::vector<uint8_t> DataParallel::broadcast_bytes(const char* what, std::vector<uint8_t> bytes) {
  at::Tensor size = at::full({1}, static_cast<int64_t>(bytes.size()), at::kLong);
  size = run(what, {size}, true);
  at::Tensor data = at::zeros({size.item<int64_t>()}, at::kByte);
  if (rank() == 0) std::copy(bytes.begin(), bytes.end(), data.data_ptr<uint8_t>());
  data = run(what, {data}, true);
  return std::vector<uint8_t>(data.data_ptr<uint8_t>(), data.data_ptr<uint8_t>() + data.numel());
}

RunFiles DataParallel::resume_files(const RunFiles& files, bool want_resume, bool* resuming) {
  *resuming = want_resume && (rank() != 0 || files.has_checkpoint());
  if (!distributed()) return files;
  *resuming = agree({*resuming ? 1.0 : 0.0})[0] > 0.5;
  if (!*resuming) return files;
  namespace fs = std::filesystem;
  if (rank() != 0) {
    scratch_ = (fs::temp_directory_path() / ("motionfield-train-rank" + std::to_string(rank()) + "-" +
                                             std::to_string(static_cast<long>(::getpid()))))
                   .string();
    fs::create_directories(scratch_);
  }
  RunFiles copies(scratch_);
  const std::pair<std::string, std::string> names[] = {{files.last_model, copies.last_model},
                                                       {files.last_optim, copies.last_optim},
                                                       {files.last_state, copies.last_state}};
  for (const auto& [original, copy] : names) {
    std::vector<uint8_t> bytes;
    if (rank() == 0) {
      std::ifstream in(original, std::ios::binary);
      bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    bytes = broadcast_bytes("sending rank 0's checkpoint", std::move(bytes));
    if (rank() != 0) {
      std::ofstream out(copy, std::ios::binary);
      out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
      if (!out) throw std::runtime_error("cannot write " + copy);
    }
  }
  return rank() == 0 ? files : copies;
}

void DataParallel::check_resumed_world_size(const TrainerState& state) const {
  if (state.world_size == world_size()) return;
  throw InputError("train: --resume: the checkpoint was trained by " + std::to_string(state.world_size) +
                   " process(es) (--world-size " + std::to_string(state.world_size) + "), this run has " +
                   std::to_string(world_size()) +
                   "; resume with the same world size (the global batch and the data order depend on it)");
}

}  // namespace training
}  // namespace mf
