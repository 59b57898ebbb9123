#include "tasks/transformer_methods.h"

#include <ATen/ATen.h>
#include <torch/types.h>

#include <algorithm>
#include <filesystem>

#include "prior/inbetween/inbetweener.h"
#include "prior/model/representation.h"
#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "tasks/initializers.h"
#include "tasks/residuals.h"

namespace mf {

namespace {

// Context before a gap, as in training: up to 10 known frames, or the
// previous key when the keys are sparse (training spaces keys up to 40 apart).
constexpr int kDenseContext = 10;
constexpr int kSparseContext = 40;

struct FillWindow {
  int start = 0;       // a key fixing the root; the canonical frame
  int owned_from = 0;  // frames (owned_from, end] are this window's output
  int end = 0;         // a key fixing the root
};

std::string kind_title(const std::string& kind) {
  return kind == kCitlKind ? "CITL transformer" : kind == kTwoStageKind ? "two-stage transformer" : kind;
}

}  // namespace

std::string inbetweener_file_name(const std::string& kind) {
  if (kind == kTwoStageKind) return kTwoStageFileName;
  if (kind == kCitlKind) return kCitlFileName;
  throw InputError("unknown transformer kind '" + kind + "' (available: twostage, citl)");
}

std::string inbetweener_path_next_to(const std::string& prior_path, const std::string& kind) {
  return (std::filesystem::path(prior_path).parent_path() / inbetweener_file_name(kind)).string();
}

std::shared_ptr<const InbetweenModel> load_frozen_inbetweener(const std::string& path, const std::string& kind) {
  std::unique_ptr<InbetweenModel> model = load_inbetweener(path);
  if (model->kind() != kind)
    throw InputError(path + " holds a '" + model->kind() + "' model, not the expected '" + kind + "'");
  model->set_requires_grad(false);
  model->train(false);
  return std::shared_ptr<const InbetweenModel>(std::move(model));
}

std::string missing_inbetweener_message(const std::string& what, const std::string& kind) {
  return what + " needs models/" + inbetweener_file_name(kind) + " (the " + kind_title(kind) +
         "), and it is not loaded: put it next to the prior's model file (train it with `motionfield-train " + kind +
         "`)";
}

Motion inbetweener_fill(const InbetweenModel& model, int stage, const Motion& input,
                        const MotionConstraints& constraints, LongGapPolicy policy) {
  const int N = input.num_frames(), J = input.num_joints();
  const RigInfo& rig = model.rig();
  if (J != rig.num_joints())
    throw InputError("the motion has " + std::to_string(J) + " joints but the " + kind_title(model.kind()) +
                     "'s skeleton has " + std::to_string(rig.num_joints()));
  constraints.validate(N, J);
  const int stages = static_cast<int>(model.stage_names().size());
  const int used_stage = stage < 0 ? stages - 1 : stage;
  if (used_stage < 0 || used_stage >= stages)
    throw InputError("the " + kind_title(model.kind()) + " has " + std::to_string(stages) + " stage(s), not stage " +
                     std::to_string(stage));

  // Reads only the constrained values; every frame holds something sensible.
  Motion out = fill_by_interpolation(input, constraints);

  std::vector<int> key_of(N, -1);
  std::vector<int> roots;
  for (size_t k = 0; k < constraints.keys.size(); ++k) {
    key_of[constraints.keys[k].frame] = static_cast<int>(k);
    if (constraints.key_fixes_root(k)) roots.push_back(constraints.keys[k].frame);
  }

  const int W = model.window();
  const int R = static_cast<int>(roots.size());
  std::vector<FillWindow> windows;
  for (int i = 0; i + 1 < R;) {
    if (roots[i + 1] - roots[i] <= 1) {
      ++i;
      continue;
    }
    if (roots[i + 1] - roots[i] + 1 > W) {
      if (policy == LongGapPolicy::Throw) {
        throw InputError("keys " + std::to_string(roots[i]) + " and " + std::to_string(roots[i + 1]) + " are " +
                         std::to_string(roots[i + 1] - roots[i]) + " frames apart, but the " +
                         kind_title(model.kind()) + " fills gaps of at most " + std::to_string(W - 2) +
                         " frames (its window holds " + std::to_string(W) +
                         "): add a key in between or use a latent solver method such as 'nemf'");
      }
      ++i;
      continue;
    }
    const auto fits = [&](int p) { return roots[i + 1] - roots[p] + 1 <= W; };
    int p = i;
    while (p > 0 && roots[p - 1] >= roots[i] - (kDenseContext - 1) && fits(p - 1)) --p;
    if (p == i && i > 0 && roots[i] - roots[i - 1] <= kSparseContext && fits(i - 1)) p = i - 1;
    int q = i + 1;
    while (q + 1 < R && roots[q + 1] - roots[p] + 1 <= W) ++q;
    windows.push_back({roots[p], roots[i], roots[q]});
    i = q;
  }
  // Constrained values exactly as given.
  const auto copy_constrained = [&](Motion* m) {
    for (size_t k = 0; k < constraints.keys.size(); ++k) {
      const PoseKey& key = constraints.keys[k];
      for (int j = 0; j < J; ++j) {
        if (constraints.key_has_joint(k, j)) m->rotation(key.frame, j) = input.rotation(key.frame, j);
      }
      if (key.root_position) m->root_positions[key.frame] = input.root_positions[key.frame];
    }
  };
  if (windows.empty()) {
    copy_constrained(&out);
    return out;
  }

  // One batch, padded to the longest window.
  at::NoGradGuard no_grad;
  const int B = static_cast<int>(windows.size());
  int L = 0;
  for (const FillWindow& w : windows) L = std::max(L, w.end - w.start + 1);
  const int D = model.pose_size();
  at::Tensor pose = at::zeros({B, L, D}, at::kFloat);
  at::Tensor known = at::zeros({B, L, J + 1}, at::kFloat);
  at::Tensor valid = at::zeros({B, L}, at::kFloat);
  std::vector<GroundTransform> transforms;
  {
    auto kn = known.accessor<float, 3>();
    auto va = valid.accessor<float, 2>();
    for (int b = 0; b < B; ++b) {
      const FillWindow& w = windows[b];
      const int T = w.end - w.start + 1;
      transforms.push_back(canonical_transform(out, w.start, rig));
      const WindowTensors wt = window_tensors(out, w.start, T, rig, 0);
      pose.select(0, b).narrow(0, 0, T).copy_(pose_features(wt.local_rotations, wt.root_positions)[0]);
      for (int t = 0; t < T; ++t) {
        va[b][t] = 1.0f;
        const int k = key_of[w.start + t];
        if (k < 0) continue;
        for (int j = 0; j < J; ++j) kn[b][t][j] = constraints.key_has_joint(static_cast<size_t>(k), j) ? 1.0f : 0.0f;
        kn[b][t][J] = constraints.keys[static_cast<size_t>(k)].root_position ? 1.0f : 0.0f;
      }
    }
  }
  // Pose channels of each joint (6) and of the root position (3) take that entry's mask.
  const at::Tensor channel_mask = at::cat({known.narrow(2, 0, J).repeat_interleave(6, 2), known.narrow(2, J, 1).expand({B, L, 3})}, 2);
  InbetweenBatch batch{pose * channel_mask, known, valid};
  const InbetweenOutput result = model.forward(batch);
  if (used_stage >= static_cast<int>(result.stages.size()))
    throw std::logic_error("the in-betweener returned fewer stages than stage_names() lists");
  const at::Tensor stage_pose = result.stages[static_cast<size_t>(used_stage)].detach().to(at::kFloat).contiguous();

  for (int b = 0; b < B; ++b) {
    const FillWindow& w = windows[b];
    const int T = w.end - w.start + 1;
    at::Tensor rotations, root;
    split_pose_features(stage_pose.narrow(0, b, 1).narrow(1, 0, T), J, &rotations, &root);
    Motion piece = Motion::identity(input.skeleton, T, input.fps);
    write_window(rotations, root, transforms[static_cast<size_t>(b)], &piece, 0);
    // The model's residual at the keys that bound each gap (given value vs the
    // model's own output there) is spread over the gap with smoothstep
    // weights, so that the output does not jump next to a key.
    std::vector<int> bounds;
    for (int f = w.owned_from; f <= w.end; ++f) {
      const int k = key_of[f];
      if (k >= 0 && constraints.key_fixes_root(static_cast<size_t>(k))) bounds.push_back(f);
    }
    std::vector<Eigen::Quaterniond> residual_a(J), residual_b(J);
    auto residual = [&](int f, std::vector<Eigen::Quaterniond>* rot, Eigen::Vector3d* rootd) {
      const size_t k = static_cast<size_t>(key_of[f]);
      for (int j = 0; j < J; ++j) {
        (*rot)[j] = constraints.key_has_joint(k, j)
                        ? Eigen::Quaterniond(input.rotation(f, j).normalized() * piece.rotation(f - w.start, j).conjugate())
                        : Eigen::Quaterniond::Identity();
      }
      *rootd = input.root_positions[f] - piece.root_positions[f - w.start];
    };
    for (size_t i = 0; i + 1 < bounds.size(); ++i) {
      const int a = bounds[i], c = bounds[i + 1];
      if (c - a < 2) continue;
      Eigen::Vector3d root_a, root_c;
      residual(a, &residual_a, &root_a);
      residual(c, &residual_b, &root_c);
      for (int f = a + 1; f < c; ++f) {
        const double s = smoothstep(static_cast<double>(f - a) / (c - a));
        for (int j = 0; j < J; ++j) {
          Eigen::Quaterniond& q = piece.rotation(f - w.start, j);
          q = (slerp(Eigen::Quaterniond::Identity(), residual_a[j], 1.0 - s) *
               slerp(Eigen::Quaterniond::Identity(), residual_b[j], s) * q)
                  .normalized();
        }
        piece.root_positions[f - w.start] += root_a * (1.0 - s) + root_c * s;
      }
    }
    for (int f = w.owned_from + 1; f <= w.end; ++f) {
      const int k = key_of[f];
      for (int j = 0; j < J; ++j) {
        if (k < 0 || !constraints.key_has_joint(static_cast<size_t>(k), j)) out.rotation(f, j) = piece.rotation(f - w.start, j);
      }
      if (k < 0 || !constraints.keys[static_cast<size_t>(k)].root_position)
        out.root_positions[f] = piece.root_positions[f - w.start];
    }
  }
  copy_constrained(&out);
  return out;
}

namespace {

Method transformer_method(const std::string& name, const std::string& description, const std::string& kind,
                          int stage) {
  Method m;
  m.name = name;
  m.description = description;
  m.needs_model = true;
  m.needs_inbetweener = kind;
  m.complete = [name, kind, stage](const Motion& input, const std::vector<int>& known, const TaskContext& ctx) {
    const InbetweenModel* model = ctx.inbetweener(kind);
    if (!model) throw InputError(missing_inbetweener_message("method '" + name + "'", kind));
    return inbetweener_fill(*model, stage, input, MotionConstraints::full_pose(known), LongGapPolicy::Throw);
  };
  return m;
}

}  // namespace

std::vector<Method> transformer_methods() {
  return {transformer_method("context", "two-stage transformer, Context Transformer only (one pass)", kTwoStageKind, 0),
          transformer_method("detail", "two-stage transformer, Context + Detail Transformer (one pass)", kTwoStageKind,
                             1),
          transformer_method("citl", "CITL transformer (one pass)", kCitlKind, -1)};
}

}  // namespace mf
