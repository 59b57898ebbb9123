#include "tasks/transformer/inbetweener_fill.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "prior/runtime/inbetween_runtime.h"
#include "prior/runtime/keyframe_runtime.h"
#include "prior/runtime/rotations.h"
#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "tasks/constraints/interpolation_fill.h"
#include "tasks/constraints/residuals.h"
#include "tasks/constraints/seams.h"
#include "tasks/fixups/foot_locking.h"
#include "tasks/transformer/inbetweener_files.h"

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

// The keys of a motion by frame.
struct KeyIndex {
  std::vector<int> key_of;  // per frame, the index of its key or -1
  std::vector<int> roots;   // frames of the keys that fix the root, increasing
};

KeyIndex index_keys(const MotionConstraints& c, int frames) {
  KeyIndex index;
  index.key_of.assign(frames, -1);
  for (size_t k = 0; k < c.keys.size(); ++k) {
    index.key_of[c.keys[k].frame] = static_cast<int>(k);
    if (c.key_fixes_root(k)) index.roots.push_back(c.keys[k].frame);
  }
  return index;
}

// Validates the call; returns the stage whose output is used.
int checked_stage(const runtime::InbetweenerRuntime& model, int stage, const Motion& input,
                  const MotionConstraints& c) {
  const int J = input.num_joints();
  const RigInfo& rig = model.rig();
  if (J != rig.num_joints())
    throw InputError("the motion has " + std::to_string(J) + " joints but the " + inbetweener_title(model.kind()) +
                     "'s skeleton has " + std::to_string(rig.num_joints()));
  c.validate(input.num_frames(), J);
  const int stages = static_cast<int>(model.stage_names().size());
  const int used_stage = stage < 0 ? stages - 1 : stage;
  if (used_stage < 0 || used_stage >= stages)
    throw InputError("the " + inbetweener_title(model.kind()) + " has " + std::to_string(stages) +
                     " stage(s), not stage " + std::to_string(stage));
  return used_stage;
}

// The windows that fill the gaps between the root-fixing keys `roots` (see
// the header): each starts at a key with its context before the gap and
// extends over as many gaps as fit in `W` frames.
std::vector<FillWindow> plan_windows(const std::vector<int>& roots, int W, LongGapPolicy policy,
                                     const std::string& title) {
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
                         std::to_string(roots[i + 1] - roots[i]) + " frames apart, but the " + title +
                         " fills gaps of at most " + std::to_string(W - 2) + " frames (its window holds " +
                         std::to_string(W) + "): add a key in between or use a latent solver method such as 'nemf'");
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
  return windows;
}

// The model's input for one window of `filled`, canonical at its start
// (runtime::InbetweenWindow: the batch of one window), and that canonical
// transform.
struct FillInput {
  runtime::InbetweenWindow window;
  GroundTransform transform;
};

std::vector<FillInput> make_inputs(const RigInfo& rig, const Motion& filled, const std::vector<FillWindow>& windows,
                                   const KeyIndex& keys, const MotionConstraints& c,
                                   const runtime::MatrixRXf& world_trajectory) {
  const int J = filled.num_joints();
  std::vector<FillInput> out;
  for (const FillWindow& w : windows) {
    const int T = w.end - w.start + 1;
    FillInput in;
    in.transform = canonical_transform(filled, w.start, rig);
    const WindowMatrices m = window_matrices(filled, w.start, T, rig, 0);
    runtime::InbetweenWindow& x = in.window;
    x.pose.resize(T, J * 6 + 3);
    x.known.setZero(T, J + 1);
    x.valid.setOnes(T);
    for (int t = 0; t < T; ++t) {
      const int k = keys.key_of[w.start + t];
      for (int j = 0; j < J && k >= 0; ++j) x.known(t, j) = c.key_has_joint(static_cast<size_t>(k), j) ? 1.0f : 0.0f;
      if (k >= 0) x.known(t, J) = c.keys[static_cast<size_t>(k)].root_position ? 1.0f : 0.0f;
      for (int j = 0; j < J; ++j) {
        const float* r = &m.local_rotations(t, j * 9);  // row-major 3x3; the 6D is its first two columns
        const float sixd[6] = {r[0], r[3], r[6], r[1], r[4], r[7]};
        for (int i = 0; i < 6; ++i) x.pose(t, j * 6 + i) = sixd[i] * x.known(t, j);
      }
      for (int i = 0; i < 3; ++i) x.pose(t, J * 6 + i) = m.root_positions(t, i) * x.known(t, J);
    }
    if (world_trajectory.rows() > 0)
      x.trajectory = canonical_trajectory(world_trajectory.middleRows(w.start, T), in.transform);
    out.push_back(std::move(in));
  }
  return out;
}

// What the model gives for one window: the used stage's raw pose [T, D] and,
// when it predicts them, its foot contact logits [T, F].
struct FillOutput {
  runtime::MatrixRXf pose;
  runtime::MatrixRXf contact_logits;
};

// One pass of the Eigen runtime's model per window.
std::vector<FillOutput> forward_runtime(const runtime::InbetweenerRuntime& net, int stage,
                                        const std::vector<FillInput>& inputs) {
  std::vector<FillOutput> out(inputs.size());
  runtime::InbetweenResult result;
  for (size_t b = 0; b < inputs.size(); ++b) {
    net.forward(inputs[b].window, &result);
    if (stage >= static_cast<int>(result.stages.size()))
      throw std::logic_error("the in-betweener returned fewer stages than stage_names() lists");
    out[b].pose = std::move(result.stages[static_cast<size_t>(stage)]);
    out[b].contact_logits = std::move(result.contact_logits);
  }
  return out;
}

// A window's canonical output (raw pose [T, D]) written into `piece`'s frames.
void write_piece(const runtime::MatrixRXf& pose, int J, const GroundTransform& transform, Motion* piece) {
  runtime::MatrixRXf rotations;
  runtime::sixd_to_matrix(pose.leftCols(J * 6), &rotations);
  write_window(rotations.cast<double>(), pose.rightCols(3).cast<double>(), transform, piece, 0);
}

// The residual at key frame f of `piece` (window frames from `start`): per
// joint given * piece^-1 where the key gives the joint (else the identity),
// and the root position's difference.
void key_residual(const Motion& input, const MotionConstraints& c, const KeyIndex& keys, const Motion& piece,
                  int start, int f, std::vector<Eigen::Quaterniond>* rotation, Eigen::Vector3d* root) {
  const size_t k = static_cast<size_t>(keys.key_of[f]);
  for (int j = 0; j < input.num_joints(); ++j) {
    (*rotation)[j] = c.key_has_joint(k, j)
                         ? Eigen::Quaterniond(input.rotation(f, j).normalized() * piece.rotation(f - start, j).conjugate())
                         : Eigen::Quaterniond::Identity();
  }
  *root = input.root_positions[f] - piece.root_positions[f - start];
}

// Spreads the model's residual at the keys that bound each gap of window `w`
// over the gap (see the header), so that the output does not jump next to a key.
void spread_gap_residuals(const Motion& input, const MotionConstraints& c, const KeyIndex& keys, const FillWindow& w,
                          Motion* piece) {
  const int J = input.num_joints();
  std::vector<int> bounds;
  for (int f = w.owned_from; f <= w.end; ++f) {
    const int k = keys.key_of[f];
    if (k >= 0 && c.key_fixes_root(static_cast<size_t>(k))) bounds.push_back(f);
  }
  std::vector<Eigen::Quaterniond> residual_a(J), residual_b(J);
  for (size_t i = 0; i + 1 < bounds.size(); ++i) {
    const int a = bounds[i], b = bounds[i + 1];
    if (b - a < 2) continue;
    Eigen::Vector3d root_a, root_b;
    key_residual(input, c, keys, *piece, w.start, a, &residual_a, &root_a);
    key_residual(input, c, keys, *piece, w.start, b, &residual_b, &root_b);
    for (int f = a + 1; f < b; ++f) {
      const double s = smoothstep(static_cast<double>(f - a) / (b - a));
      for (int j = 0; j < J; ++j) {
        Eigen::Quaterniond& q = piece->rotation(f - w.start, j);
        q = (slerp(Eigen::Quaterniond::Identity(), residual_a[j], 1.0 - s) *
             slerp(Eigen::Quaterniond::Identity(), residual_b[j], s) * q)
                .normalized();
      }
      piece->root_positions[f - w.start] += root_a * (1.0 - s) + root_b * s;
    }
  }
}

// The window's output: the unconstrained values of its frames (owned_from, end].
void take_owned_frames(const Motion& piece, const FillWindow& w, const KeyIndex& keys, const MotionConstraints& c,
                       Motion* out) {
  for (int f = w.owned_from + 1; f <= w.end; ++f) {
    const int k = keys.key_of[f];
    for (int j = 0; j < out->num_joints(); ++j) {
      if (k < 0 || !c.key_has_joint(static_cast<size_t>(k), j)) out->rotation(f, j) = piece.rotation(f - w.start, j);
    }
    if (k < 0 || !c.keys[static_cast<size_t>(k)].root_position)
      out->root_positions[f] = piece.root_positions[f - w.start];
  }
}

// The gaps of `piece` (window `w`) whose output jumps at its keys
// (implausible_seam()), set to `interpolated`'s frames and flagged in
// `jumps->frames`.
struct Jumps {
  std::vector<bool> frames;  // per frame of the motion: its gap was interpolated
  int gaps = 0;
  double worst_cm = 0.0;
};
void interpolate_jumps(const Motion& interpolated, const FillWindow& w, const KeyIndex& keys, Motion* piece,
                       Jumps* jumps) {
  std::vector<int> bounds;
  for (int f = w.owned_from; f <= w.end; ++f)
    if (keys.key_of[f] >= 0) bounds.push_back(f - w.start);
  for (const RunSeam& run : run_seams(forward_kinematics(*piece), bounds)) {
    if (!implausible_seam(run)) continue;
    ++jumps->gaps;
    jumps->worst_cm = std::max(jumps->worst_cm, run.seam_cm);
    for (int f = run.from + 1; f < run.to; ++f) {
      for (int j = 0; j < piece->num_joints(); ++j) piece->rotation(f, j) = interpolated.rotation(w.start + f, j);
      piece->root_positions[f] = interpolated.root_positions[w.start + f];
      jumps->frames[static_cast<size_t>(w.start + f)] = true;
    }
  }
}

// Constrained values exactly as given.
void copy_constrained(const Motion& input, const MotionConstraints& c, Motion* out) {
  for (size_t k = 0; k < c.keys.size(); ++k) {
    const PoseKey& key = c.keys[k];
    for (int j = 0; j < input.num_joints(); ++j) {
      if (c.key_has_joint(k, j)) out->rotation(key.frame, j) = input.rotation(key.frame, j);
    }
    if (key.root_position) out->root_positions[key.frame] = input.root_positions[key.frame];
  }
}

}  // namespace

runtime::MatrixRXf constrained_trajectory(const Motion& input, const MotionConstraints& c, const RigInfo& rig) {
  if (c.trajectory.empty()) return runtime::MatrixRXf(0, 4);
  const int n = input.num_frames();
  runtime::MatrixRXf rows = runtime::MatrixRXf::Zero(n, 4);
  std::vector<bool> xz_known(n, false), facing_known(n, false);
  for (const TrajectoryPoint& p : c.trajectory) {
    rows.row(p.frame) << static_cast<float>(p.x), static_cast<float>(p.z), static_cast<float>(p.forward_x),
        static_cast<float>(p.forward_z);
    xz_known[p.frame] = facing_known[p.frame] = true;
  }
  for (size_t k = 0; k < c.keys.size(); ++k) {
    const int f = c.keys[k].frame;
    if (c.keys[k].root_position) {
      rows(f, 0) = static_cast<float>(input.root_positions[f].x());
      rows(f, 1) = static_cast<float>(input.root_positions[f].z());
      xz_known[f] = true;
    }
    if (c.key_has_joint(k, 0)) {
      const Eigen::Matrix<float, 3, 3, Eigen::RowMajor> root =
          input.rotation(f, 0).normalized().toRotationMatrix().cast<float>();
      runtime::ground_facing(root.data(), rig, &rows(f, 2));
      facing_known[f] = true;
    }
  }
  return runtime::interpolate_trajectory_rows(rows, xz_known, facing_known);
}

runtime::MatrixRXf canonical_trajectory(const Eigen::Ref<const runtime::MatrixRXf>& world,
                                        const GroundTransform& transform) {
  if (world.cols() != 4) throw InputError("canonical_trajectory: rows must be [n, 4]");
  const double c = std::cos(transform.yaw), s = std::sin(transform.yaw);
  runtime::MatrixRXf out(world.rows(), 4);
  for (Eigen::Index t = 0; t < world.rows(); ++t) {
    const double x = world(t, 0) - transform.x, z = world(t, 1) - transform.z, fx = world(t, 2), fz = world(t, 3);
    out.row(t) << static_cast<float>(c * x - s * z), static_cast<float>(s * x + c * z),
        static_cast<float>(c * fx - s * fz), static_cast<float>(s * fx + c * fz);
  }
  return out;
}

Motion inbetweener_fill(const runtime::InbetweenerRuntime& model, int stage, const Motion& input,
                        const MotionConstraints& constraints, LongGapPolicy policy, bool foot_lock,
                        const FillFallback& fallback) {
  const int used_stage = checked_stage(model, stage, input, constraints);
  // Reads only the constrained values; every frame holds something sensible.
  Motion out = fill_by_interpolation(input, constraints);
  const Motion interpolated = fallback.interpolate_jumps ? out : Motion();
  Jumps jumps;
  jumps.frames.assign(static_cast<size_t>(input.num_frames()), false);
  std::vector<float> contacts;  // [frames, feet] when the feet are locked
  const KeyIndex keys = index_keys(constraints, input.num_frames());
  const std::vector<FillWindow> windows =
      plan_windows(keys.roots, model.window(), policy, inbetweener_title(model.kind()));
  if (!windows.empty()) {
    const std::vector<FillInput> inputs =
        make_inputs(model.rig(), out, windows, keys, constraints, constrained_trajectory(input, constraints, model.rig()));
    const std::vector<FillOutput> outputs = forward_runtime(model, used_stage, inputs);
    // The contact head reads the last stage: its contacts hold for that stage's pose only.
    const int feet = model.rig().num_feet();
    const bool lock = foot_lock && outputs.front().contact_logits.cols() == feet && feet > 0 &&
                      used_stage == static_cast<int>(model.stage_names().size()) - 1;
    if (lock) contacts.assign(static_cast<size_t>(input.num_frames()) * feet, 0.0f);
    for (size_t b = 0; b < windows.size(); ++b) {
      const FillWindow& w = windows[b];
      Motion piece = Motion::identity(input.skeleton, w.end - w.start + 1, input.fps);
      write_piece(outputs[b].pose, input.num_joints(), inputs[b].transform, &piece);
      spread_gap_residuals(input, constraints, keys, w, &piece);
      if (fallback.interpolate_jumps) interpolate_jumps(interpolated, w, keys, &piece, &jumps);
      take_owned_frames(piece, w, keys, constraints, &out);
      if (!lock) continue;
      for (int f = w.owned_from + 1; f <= w.end; ++f)
        for (int k = 0; k < feet && !jumps.frames[static_cast<size_t>(f)]; ++k)
          contacts[static_cast<size_t>(f) * feet + k] = 1.0f / (1.0f + std::exp(-outputs[b].contact_logits(f - w.start, k)));
    }
  }
  if (jumps.gaps > 0 && fallback.warnings) {
    fallback.warnings->push_back(
        "interpolation was used for " + std::to_string(jumps.gaps) + " gap(s): the " + inbetweener_title(model.kind()) +
        "'s output jumped at their keys (by up to " + std::to_string(static_cast<int>(std::lround(jumps.worst_cm))) +
        " cm in one frame), which on motion unlike its training data means interpolation is closer");
  }
  copy_constrained(input, constraints, &out);
  if (!contacts.empty()) lock_feet(model.rig(), constraints, contacts, kFootLockRamp, &out);
  return out;
}

}  // namespace mf
