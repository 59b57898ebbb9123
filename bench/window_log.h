// Per-window scores of motionfield-bench (--windows-csv): one record per
// (task row, window, method) with the window's L2P and L2Q and signals a
// method could compute at run time without the ground truth of its unknown
// frames, for studying when a learned method does worse than interpolation on
// a window (docs/experiments/2026-12-06-never-worse-signals.md):
// * l2p_to_interp: the L2P of the method's prediction measured against
//   interpolation's prediction of the same window (instead of the truth), when
//   "interp" ran on that window first;
// * key_motion_cm: how far the known frames move across the unknown runs (the
//   mean over runs of the mean joint distance between the known frames either
//   side), in cm on the model's rig;
// * seam_cm: how much the prediction jumps at its known frames beyond the
//   keys' own pace (seam_excess_cm(), tasks/constraints/seams.h), cm;
// * the method's diagnostics (TaskContext::diagnostics; the latent solvers'
//   energy terms before and after the minimisation), averaged over the
//   entries of one name (one per solved window).
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "bench/metrics.h"
#include "prior/motion/motion.h"

namespace mf::bench {

struct WindowRecord {
  std::string clip;    ///< Clip::name
  std::string task;    ///< task_name()
  std::string row;     ///< the table row: the gap T, the spacing k or the resampling label
  std::string method;
  int start = 0;       ///< the window's first frame in the clip
  double l2p = 0.0, l2q = 0.0;
  double l2p_to_interp = -1.0;  ///< -1: no interpolation of this window was logged before
  double key_motion_cm = 0.0;
  double seam_cm = 0.0;  ///< seam_excess_cm() of the prediction
  std::vector<std::pair<std::string, double>> diagnostics;  ///< averaged per name, in first-seen order
};

/// What one window's method call produced, for WindowLog::add: the truth and
/// prediction as scored (same canonical frame, the model's or native rig),
/// the frames scored and known, and the method's raw diagnostics.
struct ScoredWindow {
  const Motion* truth = nullptr;
  const Motion* pred = nullptr;
  const std::vector<int>* evaluated = nullptr;
  const std::vector<int>* known = nullptr;
  std::vector<std::pair<std::string, double>> diagnostics;
};

class WindowLog {
 public:
  /// The rig and content columns of a clip's rows.
  struct Labels {
    std::string rig, content;
  };

  /// `dataset`: the CSV's dataset column; `defaults`: the labels of clips
  /// without their own (set_labels).
  explicit WindowLog(std::string dataset, Labels defaults = {});

  void set_labels(const std::string& clip, Labels labels);

  /// Scores `w` with `stats` and records it. The prediction of "interp" is
  /// kept as the reference of the other methods on the same (clip, task, row,
  /// start). Throws mf::InputError as MetricAccumulator::add does.
  void add(const EvalStats& stats, WindowRecord record, const ScoredWindow& w);

  const std::vector<WindowRecord>& records() const { return records_; }

  /// The CSV text: a header row (dataset, rig, content, clip, task, row,
  /// method, start, l2p, l2q, l2p_to_interp, key_motion_cm, then every
  /// diagnostic name seen, sorted) and one row per record in the order added;
  /// an absent diagnostic is an empty cell.
  std::string csv() const;

  /// Writes csv() to `path`; throws std::runtime_error when it cannot.
  void write_csv(const std::string& path) const;

 private:
  std::string dataset_;
  Labels defaults_;
  std::map<std::string, Labels> labels_;
  std::vector<WindowRecord> records_;
  std::map<std::string, Motion> interp_;  ///< by reference key
};

}  // namespace mf::bench
