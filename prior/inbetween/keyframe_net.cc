#include "prior/inbetween/keyframe_net.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "prior/inbetween/keyframe_selection.h"
#include "prior/inbetween/network_model.h"
#include "prior/inbetween/transformer_blocks.h"
#include "prior/motion/errors.h"
#include "prior/motion/rotations_torch.h"
#include "prior/util/module_parameters.h"

namespace mf {

namespace {

using blocks::Positions;
using blocks::Stage;

// Facing directions [B, T, 2] interpolated between the frames where `known`
// holds and normalised; where that cancels out, the previous known facing (the
// next one before the first, +z without any).
at::Tensor interpolated_facing(const at::Tensor& facing, const at::Tensor& known) {
  const int64_t T = facing.size(1);
  at::Tensor f = blocks::interpolate_known(facing, known);
  at::Tensor prev = blocks::nearest_flagged(known, true, -1), next = blocks::nearest_flagged(known, false, T);
  at::Tensor index = at::where(prev >= 0, prev, next).clamp(0, T - 1).unsqueeze(-1).expand({-1, -1, 2});
  at::Tensor held = at::where(known.unsqueeze(-1), facing, at::zeros_like(facing)).gather(1, index);
  at::Tensor plus_z = at::zeros_like(held);
  plus_z.select(-1, 1).fill_(1.0);
  at::Tensor held_norm = held.norm(2, -1, true);
  at::Tensor fallback = at::where(held_norm > kMinFacingNorm, held / held_norm.clamp_min(kMinFacingNorm), plus_z);
  at::Tensor norm = f.norm(2, -1, true);
  return at::where(norm > kMinFacingNorm, f / norm.clamp_min(kMinFacingNorm), fallback);
}

}  // namespace

at::Tensor select_keyframes(const at::Tensor& logits, const at::Tensor& anchors, const at::Tensor& valid,
                            int min_spacing, int max_spacing) {
  if (min_spacing < 1 || max_spacing < 2 * min_spacing) {
    throw InputError("select_keyframes: need 1 <= min_spacing and 2 * min_spacing <= max_spacing");
  }
  if (logits.dim() != 2 || !anchors.sizes().equals(logits.sizes()) || !valid.sizes().equals(logits.sizes())) {
    throw InputError("select_keyframes: logits, anchors and valid must be [B, T] alike");
  }
  at::Tensor s = logits.detach().to(at::kFloat).contiguous().cpu();
  at::Tensor a = anchors.to(at::kBool).contiguous().cpu();
  at::Tensor v = (valid.detach().to(at::kFloat) > 0.5).contiguous().cpu();
  const int64_t B = logits.size(0), T = logits.size(1);
  at::Tensor out = at::zeros({B, T}, at::kBool);
  for (int64_t b = 0; b < B; ++b) {
    const float* sb = s[b].data_ptr<float>();
    const bool* ab = a[b].data_ptr<bool>();
    const bool* vb = v[b].data_ptr<bool>();
    bool* ob = out[b].data_ptr<bool>();
    select_window_keyframes(sb, ab, vb, static_cast<int>(T), min_spacing, max_spacing, ob);
  }
  return out.to(logits.device());
}

at::Tensor interpolate_keyframes(const at::Tensor& poses, const at::Tensor& keys, int num_joints) {
  const int64_t B = poses.size(0), T = poses.size(1), J = num_joints, D = J * 6 + 3;
  if (poses.dim() != 3 || poses.size(2) != D || keys.dim() != 2 || keys.size(0) != B || keys.size(1) != T) {
    throw InputError("interpolate_keyframes: poses must be [B, T, " + std::to_string(D) + "] and keys [B, T]");
  }
  at::Tensor k = keys.to(at::kBool);
  at::Tensor prev = blocks::nearest_flagged(k, true, -1);
  at::Tensor next = blocks::nearest_flagged(k, false, T);
  // Outside the keys: hold the nearest one.
  at::Tensor p = at::where(prev >= 0, prev, next).clamp(0, T - 1);
  at::Tensor n = at::where(next < T, next, prev).clamp(0, T - 1);
  at::Tensor t = at::arange(T, at::kLong).unsqueeze(0);
  at::Tensor w = ((t - p).to(poses.scalar_type()) / (n - p).clamp_min(1).to(poses.scalar_type()))
                     .clamp(0.0, 1.0);  // [B, T]
  auto gather = [&](const at::Tensor& x, const at::Tensor& index) {
    std::vector<int64_t> shape(x.sizes().begin(), x.sizes().end());
    at::Tensor i = index;
    for (size_t d = 2; d < shape.size(); ++d) i = i.unsqueeze(-1);
    return x.gather(1, i.expand(shape));
  };
  at::Tensor q = torch_rot::matrix_to_quat(
      torch_rot::sixd_to_matrix(poses.narrow(-1, 0, 6 * J).unflatten(-1, {J, 6})));  // [B, T, J, 4]
  at::Tensor root = poses.narrow(-1, 6 * J, 3);
  at::Tensor qs = torch_rot::quat_slerp(gather(q, p), gather(q, n), w.unsqueeze(-1).unsqueeze(-1));
  at::Tensor six = torch_rot::matrix_to_sixd(torch_rot::quat_to_matrix(qs)).flatten(-2);
  at::Tensor r = gather(root, p) + (gather(root, n) - gather(root, p)) * w.unsqueeze(-1);
  return at::cat({six, r}, -1);
}

at::Tensor interpolated_trajectory(const at::Tensor& pose, const at::Tensor& known, const RigInfo& rig) {
  const int64_t J = rig.num_joints();
  at::Tensor rotations, root;
  split_pose_features(pose, static_cast<int>(J), &rotations, &root);
  at::Tensor features = trajectory_features(rotations.select(2, 0), root, rig.root_forward);  // [B, T, 4]
  return interpolate_trajectory_rows(features, known.select(-1, J) > 0.5, known.select(-1, 0) > 0.5);
}

at::Tensor interpolate_trajectory_rows(const at::Tensor& rows, const at::Tensor& xz_known,
                                       const at::Tensor& facing_known) {
  if (rows.dim() != 3 || rows.size(2) != kTrajectorySize || !xz_known.sizes().equals(rows.sizes().slice(0, 2)) ||
      !facing_known.sizes().equals(rows.sizes().slice(0, 2))) {
    throw InputError("interpolate_trajectory_rows: rows must be [B, T, 4] and the known flags [B, T]");
  }
  at::Tensor xz = blocks::interpolate_known(rows.narrow(-1, 0, 2), xz_known.to(at::kBool));
  at::Tensor facing = interpolated_facing(rows.narrow(-1, 2, 2), facing_known.to(at::kBool));
  return at::cat({xz, facing}, -1);
}

namespace {

struct KeyframeNetImpl : torch::nn::Module {
  KeyframeNetImpl(const KeyframeConfig& c, const RigInfo& rig)
      : config(c), rig(rig), joints(rig.num_joints()), feet(rig.num_feet()), pose_size(joints * 6 + 3) {
    const int inputs = pose_size + joints + 1 + kTrajectorySize;
    keyframe = register_module("keyframe", Stage(c.trunk(), inputs, pose_size + 1, true));
    refine = register_module("refine", Stage(c.trunk(), inputs + 1, pose_size + feet, false));
    torch::NoGradGuard no_grad;
    refine->output->fc2->weight.mul_(0.1);  // RefineNet starts close to the identity
    refine->output->fc2->bias.zero_();
  }

  // The trajectory's inputs [B, T, 4]: ground x, z z-scored like the root position's x, z.
  at::Tensor trajectory_inputs(const at::Tensor& trajectory, const at::Tensor& mean, const at::Tensor& scale) const {
    const int64_t r = 6 * joints;
    at::Tensor m = at::stack({mean[r], mean[r + 2]}), s = at::stack({scale[r], scale[r + 2]});
    return at::cat({(trajectory.narrow(-1, 0, 2) - m) / s, trajectory.narrow(-1, 2, 2)}, -1);
  }

  // pose [B, T, D] raw; known [B, T, J + 1]; valid [B, T]; trajectory [B, T, 4]; mean/std [D].
  InbetweenOutput forward(const at::Tensor& pose, const at::Tensor& known_in, const at::Tensor& valid,
                          const at::Tensor& trajectory, bool trajectory_given, const at::Tensor& mean,
                          const at::Tensor& scale) {
    const int64_t J = joints, D = pose_size;
    at::Tensor known = known_in * valid.unsqueeze(-1);
    at::Tensor channel_known = known_channel_mask(known, joints) > 0.5;  // [B, T, D]
    at::Tensor zero = at::zeros({1}, pose.options());
    at::Tensor rotations = at::where(channel_known.narrow(-1, 0, 6 * J), ((pose - mean) / scale).narrow(-1, 0, 6 * J),
                                     zero);
    at::Tensor root_in = blocks::interpolate_known(pose.narrow(-1, 6 * J, 3), known.select(-1, J) > 0.5);
    at::Tensor x = at::cat({rotations, (root_in - mean.narrow(0, 6 * J, 3)) / scale.narrow(0, 6 * J, 3)}, -1);
    at::Tensor traj = at::where(valid.unsqueeze(-1) > 0.5, trajectory_inputs(trajectory, mean, scale), zero);

    at::Tensor key = known.amax(-1) > 0.5;
    at::Tensor valid_mask = blocks::additive_mask(valid > 0.5, pose.options());
    Positions positions = blocks::make_positions(pose.size(1), config.window, pose.options());
    at::Tensor key_encoding = blocks::key_features(key, config.window);
    at::Tensor k_out = keyframe->forward(at::cat({x, known, traj}, -1), key_encoding, valid_mask, positions);
    at::Tensor k_pose = k_out.narrow(-1, 0, D) * scale + mean;  // raw
    at::Tensor logits = k_out.select(-1, D);

    // Selection and interpolation through the known values and KeyframeNet's picks.
    at::Tensor picked = select_keyframes(logits, key, valid, config.min_spacing, config.max_spacing);
    at::Tensor anchors = key | picked | last_valid(valid);
    at::Tensor predicted = k_pose.detach();
    if (trajectory_given) predicted = follow_trajectory(predicted, trajectory, joints, rig.root_forward);
    at::Tensor key_pose = at::where(channel_known, pose, predicted);
    at::Tensor interpolated = interpolate_keyframes(key_pose, anchors & (valid > 0.5), joints);

    at::Tensor i_norm = (interpolated - mean) / scale;
    at::Tensor flags = anchors.to(pose.scalar_type()).unsqueeze(-1);
    at::Tensor r_out = refine->forward(at::cat({i_norm, known, traj, flags}, -1), at::Tensor(), valid_mask, positions);

    InbetweenOutput out;
    out.stages.push_back(interpolated);
    out.stages.push_back((i_norm + r_out.narrow(-1, 0, D)) * scale + mean);
    out.contact_logits = r_out.narrow(-1, D, feet);
    out.keyframe_poses = k_pose;
    out.keyframe_logits = logits;
    out.keyframes = (anchors & (valid > 0.5)).to(pose.scalar_type());
    return out;
  }

  // Poses [B, T, D] (raw) moved onto the trajectory: root ground x, z set to
  // the trajectory's, the root rotation turned about +Y to its facing.
  static at::Tensor follow_trajectory(const at::Tensor& pose, const at::Tensor& trajectory, int joints,
                                      const Eigen::Vector3d& root_forward) {
    const int64_t J = joints;
    at::Tensor rotations, root;
    split_pose_features(pose, joints, &rotations, &root);
    at::Tensor facing = trajectory_features(rotations.select(2, 0), root, root_forward).narrow(-1, 2, 2);
    at::Tensor delta = at::atan2(trajectory.select(-1, 2), trajectory.select(-1, 3)) -
                       at::atan2(facing.select(-1, 0), facing.select(-1, 1));  // [B, T]
    at::Tensor c = at::cos(delta), s = at::sin(delta), zero = at::zeros_like(delta), one = at::ones_like(delta);
    at::Tensor turn = at::stack({c, zero, s, zero, one, zero, -s, zero, c}, -1).unflatten(-1, {3, 3});
    at::Tensor root_rotation = torch_rot::matmul3(turn, rotations.select(2, 0));
    at::Tensor moved_root = at::stack({trajectory.select(-1, 0), root.select(-1, 1), trajectory.select(-1, 1)}, -1);
    return at::cat({torch_rot::matrix_to_sixd(root_rotation), pose.narrow(-1, 6, 6 * (J - 1)), moved_root}, -1);
  }

  // [B, T] bool: the last valid frame of each row.
  static at::Tensor last_valid(const at::Tensor& valid) {
    const int64_t T = valid.size(1);
    at::Tensor v = valid > 0.5;
    at::Tensor t = at::arange(T, at::kLong).unsqueeze(0);
    at::Tensor last = at::where(v, t, at::full_like(t, -1)).amax(1, true);
    return t == last;
  }

  KeyframeConfig config;
  RigInfo rig;
  int joints, feet, pose_size;
  Stage keyframe{nullptr}, refine{nullptr};
};
TORCH_MODULE(KeyframeNet);

class KeyframeModel final : public NetworkModel<KeyframeConfig, KeyframeNet> {
 public:
  KeyframeModel(const KeyframeConfig& config, const RigInfo& rig)
      : NetworkModel(config, rig, KeyframeNet(config, rig)) {}

  std::string kind() const override { return kKeyframeKind; }
  std::vector<std::string> stage_names() const override { return {"keyframe", "refine"}; }
  std::string describe() const override {
    std::ostringstream s;
    s << "keyframe: KeyframeNet " << config_.layers << "x" << config_.width << ", RefineNet " << config_.layers << "x"
      << config_.width << ", " << config_.heads << " heads, ffn " << config_.ffn << ", keyframes every "
      << config_.min_spacing << ".." << config_.max_spacing << " frames, window " << config_.window << " frames at "
      << config_.fps << " fps";
    return s.str();
  }

  InbetweenOutput forward(const InbetweenBatch& batch) const override {
    const Normalisation n = checked_normalisation(batch, config_.window, "keyframe");
    const int64_t D = pose_size();
    at::Tensor pose = batch.pose.to(at::kFloat), known = batch.known.to(n.options);
    at::Tensor trajectory;
    if (batch.trajectory.defined()) {
      const int64_t B = pose.size(0), T = pose.size(1);
      if (batch.trajectory.sizes() != at::IntArrayRef{B, T, kTrajectorySize}) {
        throw InputError("keyframe: trajectory must be [B, T, 4] matching pose");
      }
      trajectory = batch.trajectory.to(n.options);
    } else {
      at::NoGradGuard no_grad;
      trajectory = interpolated_trajectory(pose, known * batch.valid.to(n.options).unsqueeze(-1), rig());
    }
    return net_->forward(pose, known, batch.valid.to(n.options), trajectory, batch.trajectory.defined(), n.mean.reshape({D}),
                         n.scale.reshape({D}));
  }
};

}  // namespace

std::unique_ptr<InbetweenModel> make_keyframe_net(const std::map<std::string, double>& hyperparameters,
                                                  const RigInfo& rig) {
  return make_network_model<KeyframeModel>("keyframe", parse_keyframe_config(hyperparameters), rig);
}

int64_t keyframe_net_parameter_count(const std::map<std::string, double>& hyperparameters, const RigInfo& rig) {
  const KeyframeConfig c = parse_keyframe_config(hyperparameters);
  const int pose_size = rig.num_joints() * 6 + 3, inputs = pose_size + rig.num_joints() + 1 + kTrajectorySize;
  return blocks::stage_parameter_count(c.trunk(), inputs, pose_size + 1, true) +
         blocks::stage_parameter_count(c.trunk(), inputs + 1, pose_size + rig.num_feet(), false);
}

InbetweenNetwork keyframe_net_network() { return {make_keyframe_net, keyframe_net_parameter_count}; }

}  // namespace mf
