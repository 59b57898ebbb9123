#include "bench/protocol.h"
#include <ATen/ATen.h>

#include <ATen/Parallel.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <cstdio>
#include <sstream>

#include "prior/motion/errors.h"
#include "bench/text.h"
#include "bench/synthetic_rigs.h"
#include "prior/model/representation.h"
#include "tasks/methods/jobs.h"

namespace mf::bench {
namespace {

using Clock = std::chrono::steady_clock;

void check_prediction(const Motion& pred, const Motion& truth, const std::string& method) {
  if (pred.num_frames() != truth.num_frames() || pred.num_joints() != truth.num_joints()) {
    std::ostringstream msg;
    msg << "method " << method << " returned " << pred.num_frames() << " frames of " << pred.num_joints()
        << " joints, expected " << truth.num_frames() << " frames of " << truth.num_joints();
    throw InputError(msg.str());
  }
}

TaskResult start_result(Task task, const std::string& method) {
  TaskResult result;
  result.task = task;
  result.method = method;
  result.threads = at::get_num_threads();
  return result;
}

// The method's prediction for `input` (native rig, frames outside `known`
// hidden) through `run(input, known)`; with options.rig, on that rig and back.
Motion predict(const Motion& truth, const std::vector<int>& known, const ProtocolOptions& options,
               const std::function<Motion(const Motion&, const std::vector<int>&)>& run) {
  if (options.rig.empty()) return run(hide_unknown_frames(truth, known), known);
  if (!options.rig_anatomy) throw InputError("--rig needs the model's rig anatomy (" + options.rig + ")");
  const RigVariant v = rig_variant(options.rig);
  const VariantMotion on_rig = make_variant(truth, *options.rig_anatomy, v);
  const int ratio = static_cast<int>(std::lround(on_rig.motion.fps / truth.fps));
  if (ratio < 1 || std::abs(on_rig.motion.fps - ratio * truth.fps) > 1e-6 * truth.fps)
    throw InputError("rig '" + v.name + "' runs at " + std::to_string(on_rig.motion.fps) +
                     " fps, not a whole multiple of the benchmark's");
  // Known frames at the rig's rate: runs of consecutive known frames stay runs.
  std::vector<int> known_on_rig;
  for (size_t i = 0; i < known.size(); ++i) {
    const bool run_continues = i + 1 < known.size() && known[i + 1] == known[i] + 1;
    for (int r = 0; r < (run_continues ? ratio : 1); ++r) known_on_rig.push_back(known[i] * ratio + r);
  }
  const Motion pred = run(hide_unknown_frames(on_rig.motion, known_on_rig), known_on_rig);
  // Back to the native rig, exactly: both anatomies from the whole truth.
  RigMap map = map_rig(on_rig.motion.skeleton, truth.skeleton);
  RigAnatomy rig_anatomy = estimate_anatomy(on_rig.motion, map.user_parts);
  const Retargeter back(on_rig.motion.skeleton, truth.skeleton, map, std::move(rig_anatomy),
                        estimate_anatomy(truth, find_rig_parts(truth.skeleton)));
  const Motion native = back.to_model(pred);
  Motion out = Motion::identity(truth.skeleton, truth.num_frames(), truth.fps);
  for (int f = 0; f < truth.num_frames(); ++f) {
    out.root_positions[f] = native.root_positions[f * ratio];
    for (int j = 0; j < truth.num_joints(); ++j) out.rotation(f, j) = native.rotation(f * ratio, j);
  }
  return out;
}

using RunFn = std::function<Motion(const Motion&, const std::vector<int>&)>;

// The truth and the prediction of window `w` with frames `known` given,
// canonicalised at `anchor` (for the metrics, on the native or the model's rig).
std::pair<Motion, Motion> predict_window(const std::vector<Clip>& clips, const Window& w, int anchor,
                                         const std::vector<int>& known, const ProtocolOptions& options,
                                         const RunFn& run, const std::string& method) {
  const Motion raw = clips[w.clip].motion.slice(w.start, w.start + w.length);
  if (options.clip_to_model.empty()) {
    Motion truth = canonicalise(raw, anchor, options.root_forward);
    Motion pred = predict(truth, known, options, run);
    return {std::move(truth), std::move(pred)};
  }
  const Motion pred_user = run(hide_unknown_frames(raw, known), known);
  check_prediction(pred_user, raw, method);
  const Retargeter& to_model = *options.clip_to_model.at(w.clip);
  const Motion truth = to_model.to_model(raw);
  const RigidTransform t = canonical_transform(truth, anchor, options.root_forward);
  return {transform_motion(truth, t), transform_motion(to_model.to_model(pred_user), t)};
}

// `ctx`, with a sink for the method's diagnostics when windows are logged.
TaskContext logging_context(const TaskContext& ctx, const ProtocolOptions& options,
                            std::vector<std::pair<std::string, double>>* diagnostics) {
  TaskContext c = ctx;
  if (options.window_log) c.diagnostics = diagnostics;
  return c;
}

// Records a scored window in options.window_log and options.feature_sets, when set.
void log_window(const ProtocolOptions& options, const EvalStats& stats, const Clip& clip, Task task,
                const std::string& row, const Window& w, const std::string& method, ScoredWindow scored) {
  if (options.features && options.feature_sets)
    options.feature_sets->add(std::string(task_name(task)) + " " + row + " / " + method,
                              options.features->features(*scored.truth), options.features->features(*scored.pred));
  if (!options.window_log) return;
  WindowRecord r;
  r.clip = clip.name;
  r.task = task_name(task);
  r.row = row;
  r.method = method;
  r.start = w.start;
  options.window_log->add(stats, std::move(r), scored);
}

}  // namespace

const char* task_name(Task task) {
  switch (task) {
    case Task::Gap: return "gap";
    case Task::Sparse: return "sparse";
    case Task::Resample: return "resample";
  }
  return "?";
}

Task task_from_name(const std::string& name) {
  for (Task t : all_tasks()) {
    if (name == task_name(t)) return t;
  }
  throw InputError("unknown task '" + name + "' (expected gap, sparse or resample)");
}

std::vector<Task> all_tasks() { return {Task::Gap, Task::Sparse, Task::Resample}; }

std::vector<Window> protocol_windows(const std::vector<Clip>& clips, int length, int stride) {
  if (length < 1 || stride < 1) throw InputError("protocol windows need length >= 1 and stride >= 1");
  std::vector<Window> windows;
  for (size_t c = 0; c < clips.size(); ++c) {
    const int frames = clips[c].motion.num_frames();
    for (int start = 0; start + length <= frames; start += stride) {
      windows.push_back({static_cast<int>(c), start, length});
    }
  }
  return windows;
}

std::vector<Window> cap_windows(const std::vector<Window>& windows, int max_windows) {
  const size_t n = windows.size();
  if (max_windows <= 0 || n <= static_cast<size_t>(max_windows)) return windows;
  std::vector<Window> out;
  out.reserve(max_windows);
  for (size_t i = 0; i < static_cast<size_t>(max_windows); ++i) out.push_back(windows[i * n / max_windows]);
  return out;
}

std::vector<int> sparse_keyframes(int frames, int spacing) {
  if (spacing < 1 || frames < 2) throw InputError("sparse keyframes need spacing >= 1 and at least 2 frames");
  std::vector<int> keys;
  for (int f = 0; f < frames - 1; f += spacing) keys.push_back(f);
  keys.push_back(frames - 1);
  return keys;
}

Motion hide_unknown_frames(const Motion& motion, const std::vector<int>& known) {
  if (known.empty()) throw InputError("hide_unknown_frames: no known frame");
  Motion out = motion;
  std::vector<char> is_known(motion.num_frames(), 0);
  for (int f : known) {
    if (f < 0 || f >= motion.num_frames()) throw InputError("hide_unknown_frames: known frame out of range");
    is_known[f] = 1;
  }
  Eigen::Vector3d last_root = motion.root_positions[known.front()];
  for (int f = 0; f < motion.num_frames(); ++f) {
    if (is_known[f]) {
      last_root = motion.root_positions[f];
      continue;
    }
    out.root_positions[f] = last_root;
    for (int j = 0; j < motion.num_joints(); ++j) out.rotation(f, j) = Eigen::Quaterniond::Identity();
  }
  return out;
}

std::vector<TrajectoryPoint> truth_trajectory(const Motion& truth, int a, int b, const Eigen::Vector3d& root_forward) {
  std::vector<int> frames;
  for (int f = a; f < b; ++f) frames.push_back(f);
  if (frames.empty()) return {};
  at::Tensor r = at::empty({b - a, 3, 3}, at::kDouble), p = at::empty({b - a, 3}, at::kDouble);
  for (int f = a; f < b; ++f) {
    const Eigen::Matrix3d q = truth.rotation(f, 0).normalized().toRotationMatrix();
    for (int i = 0; i < 3; ++i) {
      p[f - a][i] = truth.root_positions[f][i];
      for (int j = 0; j < 3; ++j) r[f - a][i][j] = q(i, j);
    }
  }
  at::Tensor t = trajectory_features(r, p, root_forward).contiguous();
  std::vector<TrajectoryPoint> rows;
  for (int f = a; f < b; ++f) {
    const double* v = t[f - a].data_ptr<double>();
    rows.push_back({f, v[0], v[1], v[2], v[3]});
  }
  return rows;
}

// Gap filling of one window, with the ground-truth trajectory of the gap when
// asked and the method follows one (the others, the baselines among them, run
// without it: their rows are the references).
std::pair<Motion, Motion> fill_gap(const std::vector<Clip>& clips, const Window& w, const std::vector<int>& known,
                                   int a, int b, const std::string& method, const ProtocolOptions& options,
                                   const TaskContext& ctx) {
  const int anchor = options.context - 1;
  if (!options.trajectory || !resolve_method(method, ctx).follows_trajectory) {
    return predict_window(clips, w, anchor, known, options, [&](const Motion& input, const std::vector<int>& k) {
      const auto gap = std::adjacent_find(k.begin(), k.end(), [](int x, int y) { return y != x + 1; });
      return run_fill(input, *gap + 1, *(gap + 1), method, ctx);
    }, method);
  }
  if (!options.rig.empty() || !options.clip_to_model.empty())
    throw InputError("gap filling with a trajectory runs on the native rig only");
  Motion truth = canonicalise(clips[w.clip].motion.slice(w.start, w.start + w.length), anchor, options.root_forward);
  MotionConstraints c = MotionConstraints::full_pose(known);
  c.trajectory = truth_trajectory(truth, a, b, options.root_forward);
  Motion pred = run_constrained(hide_unknown_frames(truth, known), c, method, 0, ctx).motions.front();
  return {std::move(truth), std::move(pred)};
}

TaskResult run_gap_filling(const std::vector<Clip>& clips, const EvalStats& stats, const std::string& method,
                           const ProtocolOptions& options, const TaskContext& ctx) {
  if (options.context < 1) throw InputError("gap filling needs at least one context frame");
  TaskResult result = start_result(Task::Gap, method);
  result.trajectory = options.trajectory && resolve_method(method, ctx).follows_trajectory;
  result.l2t = options.l2t;
  for (int T : options.gap_lengths) {
    if (T < 1) throw InputError("gap lengths must be positive");
    const int length = options.context + T + 1;
    const int a = options.context, b = options.context + T;
    const std::vector<Window> windows = cap_windows(protocol_windows(clips, length, options.stride), options.max_windows);
    std::vector<int> evaluated, known;
    for (int f = 0; f < length; ++f) (f >= a && f < b ? evaluated : known).push_back(f);
    MetricAccumulator acc(stats, options.root_forward);
    double ms = 0.0;
    for (const Window& w : windows) {
      std::vector<std::pair<std::string, double>> diagnostics;
      const TaskContext window_ctx = logging_context(ctx, options, &diagnostics);
      const auto t0 = Clock::now();
      const auto [truth, pred] = fill_gap(clips, w, known, a, b, method, options, window_ctx);
      ms += ms_since(t0);
      check_prediction(pred, truth, method);
      acc.add(truth, pred, evaluated, known);
      log_window(options, stats, clips[w.clip], Task::Gap, std::to_string(T), w, method,
                 {&truth, &pred, &evaluated, &known, std::move(diagnostics)});
    }
    RowResult row;
    row.parameter = T;
    row.metrics = acc.summary();
    row.ms_per_window = windows.empty() ? 0.0 : ms / windows.size();
    result.rows.push_back(row);
  }
  return result;
}

TaskResult run_sparse_keyframes(const std::vector<Clip>& clips, const EvalStats& stats, const std::string& method,
                                const ProtocolOptions& options, const TaskContext& ctx) {
  TaskResult result = start_result(Task::Sparse, method);
  const int length = options.sparse_window;
  const std::vector<Window> windows = cap_windows(protocol_windows(clips, length, options.stride), options.max_windows);
  for (int k : options.keyframe_spacings) {
    const std::vector<int> keys = sparse_keyframes(length, k);
    std::vector<int> evaluated;
    for (int f = 0, i = 0; f < length; ++f) {
      if (i < static_cast<int>(keys.size()) && keys[i] == f) {
        ++i;
      } else {
        evaluated.push_back(f);
      }
    }
    MetricAccumulator acc(stats);
    double ms = 0.0;
    int used = 0;
    for (const Window& w : windows) {
      if (evaluated.empty()) break;  // spacing 1: nothing to evaluate
      std::vector<std::pair<std::string, double>> diagnostics;
      const TaskContext window_ctx = logging_context(ctx, options, &diagnostics);
      const auto t0 = Clock::now();
      const auto [truth, pred] = predict_window(clips, w, 0, keys, options, [&](const Motion& input, const std::vector<int>& k) {
        return run_inbetween(input, k, method, window_ctx);
      }, method);
      ms += ms_since(t0);
      check_prediction(pred, truth, method);
      acc.add(truth, pred, evaluated, keys);
      log_window(options, stats, clips[w.clip], Task::Sparse, std::to_string(k), w, method,
                 {&truth, &pred, &evaluated, &keys, std::move(diagnostics)});
      ++used;
    }
    RowResult row;
    row.parameter = k;
    row.metrics = acc.summary();
    row.ms_per_window = used == 0 ? 0.0 : ms / used;
    result.rows.push_back(row);
  }
  return result;
}

ResampleRatio parse_resample_ratio(const std::string& text) {
  ResampleRatio r;
  const size_t colon = text.find(':');
  auto whole = [&](const std::string& t) {
    size_t used = 0;
    int v = 0;
    try {
      v = std::stoi(t, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != t.size() || v < 1 || v > 1000)
      throw InputError("a resampling ratio is k or a:b with whole numbers from 1 to 1000, not '" + text + "'");
    return v;
  };
  r.in_step = whole(text.substr(0, colon));
  r.out_step = colon == std::string::npos ? 1 : whole(text.substr(colon + 1));
  if (r.in_step == r.out_step) throw InputError("a resampling ratio must change the frame rate, not '" + text + "'");
  return r;
}

std::string ResampleRatio::label() const {
  return out_step == 1 ? std::to_string(in_step) : std::to_string(in_step) + ":" + std::to_string(out_step);
}

TaskResult run_resampling(const std::vector<Clip>& clips, const EvalStats& stats, const std::string& method,
                          const ProtocolOptions& options, const TaskContext& ctx) {
  TaskResult result = start_result(Task::Resample, method);
  for (const ResampleRatio& ratio : options.resample_ratios) {
    const int a = ratio.in_step, b = ratio.out_step;
    if (a < 1 || b < 1 || a == b)
      throw InputError("resampling steps must be at least 1 and differ, not " + ratio.label());
    const int period = std::lcm(a, b);
    const int length = 1 + period * std::max(1, (options.resample_window - 1 + period - 1) / period);
    const std::vector<Window> windows = cap_windows(protocol_windows(clips, length, options.stride), options.max_windows);
    // Output frame k is ground-truth frame k * b; it is an input frame when k * b is a multiple of a.
    std::vector<int> evaluated, known;
    for (int k = 0; k * b < length; ++k) ((k * b) % a ? evaluated : known).push_back(k);
    MetricAccumulator acc(stats);
    double ms = 0.0;
    for (const Window& w : windows) {
      const bool foreign = !options.clip_to_model.empty();
      const Motion raw = clips[w.clip].motion.slice(w.start, w.start + length);
      const Motion full = foreign ? raw : canonicalise(raw, 0, options.root_forward);
      auto every = [&](int step) {
        Motion m = Motion::identity(full.skeleton, (length - 1) / step + 1, full.fps / step);
        for (int i = 0; i < m.num_frames(); ++i) {
          m.root_positions[i] = full.root_positions[i * step];
          for (int j = 0; j < full.num_joints(); ++j) m.rotation(i, j) = full.rotation(i * step, j);
        }
        return m;
      };
      const Motion input = every(a), truth_user = every(b);
      std::vector<std::pair<std::string, double>> diagnostics;
      const TaskContext window_ctx = logging_context(ctx, options, &diagnostics);
      const auto t0 = Clock::now();
      const Motion pred_user = run_resample(input, truth_user.fps, method, nullptr, window_ctx);
      ms += ms_since(t0);
      check_prediction(pred_user, truth_user, method);
      Motion truth = truth_user, pred = pred_user;
      if (foreign) {
        const Retargeter& to_model = *options.clip_to_model.at(w.clip);
        truth = to_model.to_model(truth_user);
        const RigidTransform t = canonical_transform(truth, 0, options.root_forward);
        truth = transform_motion(truth, t);
        pred = transform_motion(to_model.to_model(pred_user), t);
      }
      acc.add(truth, pred, evaluated, known);
      log_window(options, stats, clips[w.clip], Task::Resample, ratio.label(), w, method,
                 {&truth, &pred, &evaluated, &known, std::move(diagnostics)});
    }
    RowResult row;
    row.parameter = a;
    row.label = ratio.label();
    row.metrics = acc.summary();
    row.ms_per_window = windows.empty() ? 0.0 : ms / windows.size();
    result.rows.push_back(row);
  }
  return result;
}

TaskResult run_task(Task task, const std::vector<Clip>& clips, const EvalStats& stats, const std::string& method,
                    const ProtocolOptions& options, const TaskContext& ctx) {
  switch (task) {
    case Task::Gap: return run_gap_filling(clips, stats, method, options, ctx);
    case Task::Sparse: return run_sparse_keyframes(clips, stats, method, options, ctx);
    case Task::Resample: return run_resampling(clips, stats, method, options, ctx);
  }
  throw InputError("unknown task");
}

bool method_supports(const std::string& method, Task task) {
  for (const Method& m : registered_methods()) {
    if (m.name != method) continue;
    return task == Task::Resample ? static_cast<bool>(m.resample) : static_cast<bool>(m.complete);
  }
  return false;
}

std::string format_table(const TaskResult& result, bool l2p_axes) {
  std::ostringstream out;
  const char* title = "";
  const char* param = "";
  switch (result.task) {
    case Task::Gap:
      title = "Gap filling (10 context frames + T + 1 target)";
      param = "T";
      break;
    case Task::Sparse:
      title = "Sparse keyframes (128-frame windows, keyframe every k frames)";
      param = "k";
      break;
    case Task::Resample:
      title = "Resampling (every k-th frame -> full rate; a:b: every a-th frame -> every b-th)";
      param = "k";
      break;
  }
  out << "### " << title << "\n\n";
  out << "method: `" << result.method << "`, torch threads: " << result.threads
      << (result.trajectory ? ", given the ground-truth trajectory" : "") << "\n\n";
  out << "| " << param << " | windows | L2P" << (l2p_axes ? " | L2P xz | L2P y" : "") << (result.l2t ? " | L2T" : "")
      << " | L2Q | NPSS | MPJPE (cm) | skating (cm) | skating GT (cm) "
         "| known pos max / mean (cm) | known rot max / mean (deg) | ms / window |\n";
  out << "|---:|---:|---:|" << (l2p_axes ? "---:|---:|" : "") << (result.l2t ? "---:|" : "") << "---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const RowResult& row : result.rows) {
    const MetricSummary& m = row.metrics;
    out << "| " << (row.label.empty() ? std::to_string(row.parameter) : row.label) << " | " << m.windows << " | " << fixed(m.l2p, 3);
    if (l2p_axes) out << " | " << fixed(m.l2p_horizontal, 3) << " | " << fixed(m.l2p_vertical, 3);
    if (result.l2t) out << " | " << fixed(m.l2t, 3);
    out << " | " << fixed(m.l2q, 3)
        << " | " << fixed(m.npss, 4) << " | " << fixed(m.mpjpe_cm, 2) << " | " << fixed(m.skating_cm, 3) << " | "
        << fixed(m.truth_skating_cm, 3) << " | " << fixed(m.known.position_max_cm, 3) << " / "
        << fixed(m.known.position_mean_cm(), 3) << " | " << fixed(m.known.rotation_max_deg, 3) << " / "
        << fixed(m.known.rotation_mean_deg(), 3) << " | " << fixed(row.ms_per_window, 3) << " |\n";
  }
  return out.str();
}

std::string format_eval_stats(const EvalStats& stats) {
  std::ostringstream out;
  out << "| joint | mean x | mean y | mean z | std x | std y | std z | standing height | contact threshold |\n";
  out << "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (size_t j = 0; j < stats.joint_names.size() && 3 * j + 2 < stats.position_std.size(); ++j) {
    out << "| " << stats.joint_names[j];
    for (int a = 0; a < 3; ++a) out << " | " << fixed(100.0 * stats.position_mean[3 * j + a], 1);
    for (int a = 0; a < 3; ++a) out << " | " << fixed(100.0 * stats.position_std[3 * j + a], 1);
    std::string standing = " | | |";
    for (size_t i = 0; i < stats.feet.size(); ++i) {
      if (stats.feet[i].joint == static_cast<int>(j)) {
        standing = " | " + fixed(100.0 * stats.standing_height[i], 2) + " | " + fixed(stats.feet[i].threshold_cm, 0) + " |";
      }
    }
    out << standing << "\n";
  }
  out << "\nAll values in cm; positions canonicalised (see bench/metrics.h).\n";
  return out.str();
}

}  // namespace mf::bench
