#include "prior/inbetween/inbetweener.h"

#include <ATen/ATen.h>
#include <torch/types.h>

#include <cmath>
#include <mutex>
#include <sstream>
#include <utility>

#include "prior/inbetween/citl.h"
#include "prior/inbetween/keyframe_net.h"
#include "prior/inbetween/two_stage.h"
#include "prior/model/model_file.h"
#include "prior/motion/errors.h"
#include "prior/motion/kinematics_torch.h"
#include "prior/motion/rotations_torch.h"
#include "prior/util/binary_io.h"
#include "prior/util/file_writer.h"

namespace mf {

namespace {

// Loss weights (see inbetween_pose_loss in the header).
constexpr double kRotationWeight = 1.0;
constexpr double kPositionWeight = 1.0;
constexpr double kRootWeight = 1.0;
constexpr double kMinRotationStd = 0.05;

std::mutex& registry_mutex() {
  static std::mutex m;
  return m;
}
std::map<std::string, InbetweenFactory>& registry() {
  static std::map<std::string, InbetweenFactory> r;
  return r;
}

// The file kinds load_inbetweener accepts: the product's and the registered.
std::vector<std::string> known_kinds() {
  std::vector<std::string> kinds;
  for (const InbetweenerKind& k : inbetweener_kinds()) kinds.push_back(k.name);
  std::lock_guard<std::mutex> lock(registry_mutex());
  for (const auto& [k, f] : registry()) kinds.push_back(k);
  return kinds;
}

at::Tensor masked_mean(const at::Tensor& per_frame, const at::Tensor& valid) {
  return (per_frame * valid).sum() / valid.sum().clamp_min(1.0);
}

}  // namespace

at::Tensor pose_features(const at::Tensor& local_rotations, const at::Tensor& root_positions) {
  if (local_rotations.dim() < 3 || local_rotations.size(-1) != 3 || local_rotations.size(-2) != 3) {
    throw InputError("pose_features: local rotations must be [..., J, 3, 3]");
  }
  if (root_positions.size(-1) != 3) throw InputError("pose_features: root positions must be [..., 3]");
  at::Tensor six = torch_rot::matrix_to_sixd(local_rotations).flatten(-2);  // [..., J * 6]
  return at::cat({six, root_positions.to(six.scalar_type())}, -1);
}

void split_pose_features(const at::Tensor& pose, int num_joints, at::Tensor* local_rotations,
                         at::Tensor* root_positions) {
  const int64_t D = static_cast<int64_t>(num_joints) * 6 + 3;
  if (num_joints < 1 || pose.dim() < 1 || pose.size(-1) != D) {
    throw InputError("split_pose_features: pose must be [..., " + std::to_string(D) + "] for " +
                     std::to_string(num_joints) + " joints");
  }
  if (local_rotations) {
    std::vector<int64_t> shape(pose.sizes().begin(), pose.sizes().end() - 1);
    shape.push_back(num_joints);
    shape.push_back(6);
    *local_rotations = torch_rot::sixd_to_matrix(pose.narrow(-1, 0, D - 3).reshape(shape));
  }
  if (root_positions) *root_positions = pose.narrow(-1, D - 3, 3);
}

at::Tensor known_channel_mask(const at::Tensor& known, int num_joints) {
  if (known.dim() < 1 || known.size(-1) != num_joints + 1) {
    throw InputError("known_channel_mask: known must be [..., " + std::to_string(num_joints + 1) + "]");
  }
  std::vector<int64_t> root_shape(known.sizes().begin(), known.sizes().end());
  root_shape.back() = 3;
  return at::cat({known.narrow(-1, 0, num_joints).repeat_interleave(6, -1),
                  known.narrow(-1, num_joints, 1).expand(root_shape)},
                 -1);
}

InbetweenModel::InbetweenModel(const RigInfo& rig) : rig_(rig) {
  stats_.pose_mean = at::zeros({pose_size()});
  stats_.pose_std = at::ones({pose_size()});
}

InbetweenModel::Normalisation InbetweenModel::checked_normalisation(const InbetweenBatch& batch, int window,
                                                                   const std::string& name) const {
  const int64_t J = rig().num_joints(), D = pose_size();
  const at::Tensor& pose = batch.pose;
  if (!pose.defined() || pose.dim() != 3 || pose.size(2) != D) {
    throw InputError(name + ": pose must be [B, T, " + std::to_string(D) + "]");
  }
  const int64_t B = pose.size(0), T = pose.size(1);
  if (B < 1 || T < 1 || T > window) {
    throw InputError(name + ": windows must have 1 to " + std::to_string(window) + " frames (got " +
                     std::to_string(T) + ")");
  }
  if (!batch.known.defined() || batch.known.sizes() != at::IntArrayRef{B, T, J + 1}) {
    throw InputError(name + ": known must be [B, T, " + std::to_string(J + 1) + "] matching pose");
  }
  if (!batch.valid.defined() || batch.valid.sizes() != at::IntArrayRef{B, T}) {
    throw InputError(name + ": valid must be [B, T] matching pose");
  }
  Normalisation n;
  n.options = pose.options().dtype(at::kFloat);
  n.mean = stats().pose_mean.defined() ? stats().pose_mean.to(n.options) : at::zeros({D}, n.options);
  n.scale = stats().pose_std.defined() ? stats().pose_std.to(n.options) : at::ones({D}, n.options);
  if (n.mean.numel() != D || n.scale.numel() != D) throw InputError(name + ": statistics do not match the pose size");
  n.scale = n.scale.clamp_min(1e-6);  // a constant channel (std 0) must not turn the input into inf/NaN
  return n;
}

int InbetweenModel::window() const {
  auto hp = hyperparameters();
  auto it = hp.find("window");
  return it == hp.end() ? 0 : static_cast<int>(it->second);
}

double InbetweenModel::fps() const {
  auto hp = hyperparameters();
  auto it = hp.find("fps");
  return it == hp.end() ? 0.0 : it->second;
}

std::vector<at::Tensor> InbetweenModel::parameters() const {
  std::vector<at::Tensor> out;
  for (auto& [name, p] : named_parameters()) out.push_back(p);
  return out;
}

int64_t InbetweenModel::num_parameters() const {
  int64_t n = 0;
  for (auto& [name, p] : named_parameters()) n += p.numel();
  return n;
}

void InbetweenModel::set_requires_grad(bool on) {
  for (auto& [name, p] : named_parameters()) p.set_requires_grad(on);
}

const InbetweenNetwork* find_inbetween_network(const std::string& kind) {
  static const std::map<std::string, InbetweenNetwork> networks = {
      {kTwoStageKind, two_stage_network()}, {kCitlKind, citl_network()}, {kKeyframeKind, keyframe_net_network()}};
  auto it = networks.find(kind);
  return it == networks.end() ? nullptr : &it->second;
}

void register_inbetweener_kind(const std::string& kind, InbetweenFactory factory) {
  if (find_inbetweener_kind(kind) || kind == kNemfKind || kind.empty()) {
    throw InputError("register_inbetweener_kind: '" + kind + "' is reserved");
  }
  std::lock_guard<std::mutex> lock(registry_mutex());
  registry()[kind] = std::move(factory);
}

std::unique_ptr<InbetweenModel> make_inbetweener(const std::string& kind,
                                                 const std::map<std::string, double>& hyperparameters,
                                                 const RigInfo& rig) {
  if (rig.num_joints() < 1) throw InputError("in-betweener: the rig has no joints");
  InbetweenFactory factory;
  if (const InbetweenNetwork* k = find_inbetween_network(kind)) {
    factory = k->make;
  } else {
    std::lock_guard<std::mutex> lock(registry_mutex());
    auto it = registry().find(kind);
    if (it != registry().end()) factory = it->second;
  }
  if (!factory) {
    std::string list;
    for (const InbetweenerKind& k : inbetweener_kinds()) list += (list.empty() ? "'" : ", '") + k.name + "'";
    throw InputError("unknown in-betweener kind '" + kind + "' (expected " + list + ")");
  }
  std::unique_ptr<InbetweenModel> model = factory(hyperparameters, rig);
  if (!model) throw InputError("in-betweener: the factory of '" + kind + "' made no model");
  return model;
}

std::vector<uint8_t> serialize_inbetweener(const InbetweenModel& model) {
  std::vector<std::pair<std::string, at::Tensor>> tensors = {{"stats.pose_mean", model.stats().pose_mean},
                                                             {"stats.pose_std", model.stats().pose_std}};
  for (auto& named : model.named_parameters()) tensors.push_back(named);
  return serialize_model_file(model.kind(), model.hyperparameters(), model.rig(), tensors);
}

std::unique_ptr<InbetweenModel> deserialize_inbetweener(const uint8_t* data, size_t size, const std::string& source) {
  ModelFileContents c = parse_model_file(data, size, source, known_kinds());
  check_window_and_fps(c.hyperparameters, source);
  // Hyperparameters within their bounds can still describe a network of
  // billions of parameters; building it would take minutes and gigabytes
  // before the first tensor's shape is found wrong, so the count comes first.
  const InbetweenerKind* kind = find_inbetweener_kind(c.kind);
  const InbetweenNetwork* network = find_inbetween_network(c.kind);
  if (kind && network && network->count_parameters) {
    int64_t wanted = 0, held = 0;
    try {
      wanted = network->count_parameters(c.hyperparameters, c.rig);
    } catch (const InputError& e) {
      throw InputError(source + ": invalid hyperparameters: " + e.what());
    }
    for (const auto& [name, tensor] : c.tensors) held += tensor.numel();
    if (wanted > held) {
      throw InputError(source + ": invalid hyperparameters: they describe a " + kind->title + " of " +
                       std::to_string(wanted) + " parameters, but the file holds " + std::to_string(held) +
                       " values");
    }
  }
  std::unique_ptr<InbetweenModel> model;
  try {
    model = make_inbetweener(c.kind, c.hyperparameters, c.rig);
  } catch (const InputError& e) {
    throw InputError(source + ": invalid hyperparameters: " + e.what());
  }
  take_model_tensor(c.tensors, "stats.pose_mean", model->stats().pose_mean, source);
  take_model_tensor(c.tensors, "stats.pose_std", model->stats().pose_std, source);
  for (auto& [name, param] : model->named_parameters()) take_model_tensor(c.tensors, name, param, source);
  check_no_extra_tensors(c.tensors, source);
  model->train(false);
  return model;
}

void save_inbetweener(const InbetweenModel& model, const std::string& path) {
  write_file_atomically(path, serialize_inbetweener(model));
}

std::unique_ptr<InbetweenModel> load_inbetweener(const std::string& path) {
  const FileBytes bytes = read_file_bytes(path);
  return deserialize_inbetweener(bytes.data(), bytes.size(), path);
}

at::Tensor inbetween_pose_loss(const InbetweenModel& model, const at::Tensor& predicted, const at::Tensor& target,
                               const at::Tensor& valid, InbetweenLossParts* parts) {
  const RigInfo& rig = model.rig();
  const int J = rig.num_joints();
  const int64_t D = model.pose_size();
  if (predicted.dim() != 3 || predicted.size(-1) != D || !predicted.sizes().equals(target.sizes()) ||
      valid.dim() != 2 || valid.size(0) != predicted.size(0) || valid.size(1) != predicted.size(1)) {
    throw InputError("inbetween_pose_loss: expected predicted/target [B, T, " + std::to_string(D) +
                     "] and valid [B, T]");
  }
  at::Tensor v = valid.to(predicted.scalar_type());
  at::Tensor inv_std = 1.0 / model.stats().pose_std.narrow(0, 0, D - 3).clamp_min(kMinRotationStd);
  at::Tensor rot = ((predicted.narrow(-1, 0, D - 3) - target.narrow(-1, 0, D - 3)).abs() * inv_std).mean(-1);

  at::Tensor r_pred, p_pred, r_tgt, p_tgt;
  split_pose_features(predicted, J, &r_pred, &p_pred);
  split_pose_features(target, J, &r_tgt, &p_tgt);
  at::Tensor offsets = offsets_tensor(rig.skeleton).to(predicted.scalar_type());
  at::Tensor g_pred = forward_kinematics(rig.skeleton.parents, offsets, r_pred, p_pred).positions;
  at::Tensor g_tgt = forward_kinematics(rig.skeleton.parents, offsets, r_tgt, p_tgt).positions;
  at::Tensor pos = (g_pred - g_tgt).abs().flatten(-2).mean(-1);
  at::Tensor root = (p_pred - p_tgt).abs().mean(-1);

  InbetweenLossParts p{masked_mean(rot, v), masked_mean(pos, v), masked_mean(root, v)};
  at::Tensor total = kRotationWeight * p.rotation + kPositionWeight * p.position + kRootWeight * p.root;
  if (parts) *parts = p;
  return total;
}

}  // namespace mf
