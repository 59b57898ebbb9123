#include "bench/window_log.h"

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "tasks/constraints/seams.h"
#include "tasks/latent/fallback.h"

namespace mf::bench {
namespace {

std::string reference_key(const WindowRecord& r) {
  return r.clip + "\n" + r.task + "\n" + r.row + "\n" + std::to_string(r.start);
}

// Averages the entries of each name, keeping the order names first appear in.
std::vector<std::pair<std::string, double>> mean_per_name(const std::vector<std::pair<std::string, double>>& raw) {
  std::vector<std::pair<std::string, double>> out;
  std::vector<int> counts;
  for (const auto& [name, value] : raw) {
    auto it = std::find_if(out.begin(), out.end(), [&](const auto& e) { return e.first == name; });
    if (it == out.end()) {
      out.emplace_back(name, value);
      counts.push_back(1);
    } else {
      it->second += value;
      ++counts[it - out.begin()];
    }
  }
  for (size_t i = 0; i < out.size(); ++i) out[i].second /= counts[i];
  return out;
}

double window_l2p(const EvalStats& stats, const Motion& truth, const Motion& pred, const ScoredWindow& w,
                  double* l2q) {
  MetricAccumulator acc(stats);
  acc.add(truth, pred, *w.evaluated, *w.known);
  const MetricSummary s = acc.summary();
  if (l2q) *l2q = s.l2q;
  return s.l2p;
}

}  // namespace

WindowLog::WindowLog(std::string dataset, Labels defaults) : dataset_(std::move(dataset)), defaults_(std::move(defaults)) {}

void WindowLog::set_labels(const std::string& clip, Labels labels) { labels_[clip] = std::move(labels); }

void WindowLog::add(const EvalStats& stats, WindowRecord r, const ScoredWindow& w) {
  r.l2p = window_l2p(stats, *w.truth, *w.pred, w, &r.l2q);
  r.key_motion_cm = key_motion_cm(*w.truth, *w.known);
  r.seam_cm = seam_excess_cm(*w.pred, *w.known);
  r.diagnostics = mean_per_name(w.diagnostics);
  const std::string key = reference_key(r);
  if (r.method == "interp") {
    interp_.insert_or_assign(key, *w.pred);
  } else if (auto it = interp_.find(key); it != interp_.end()) {
    r.l2p_to_interp = window_l2p(stats, it->second, *w.pred, w, nullptr);
  }
  records_.push_back(std::move(r));
}

std::string WindowLog::csv() const {
  std::set<std::string> names;
  for (const WindowRecord& r : records_)
    for (const auto& d : r.diagnostics) names.insert(d.first);
  std::ostringstream out;
  out.precision(9);
  out << "dataset,rig,content,clip,task,row,method,start,l2p,l2q,l2p_to_interp,key_motion_cm,seam_cm";
  for (const std::string& n : names) out << "," << n;
  out << "\n";
  for (const WindowRecord& r : records_) {
    auto l = labels_.find(r.clip);
    const Labels& labels = l == labels_.end() ? defaults_ : l->second;
    out << dataset_ << "," << labels.rig << "," << labels.content << "," << r.clip << "," << r.task << "," << r.row
        << "," << r.method << "," << r.start << "," << r.l2p << "," << r.l2q << ",";
    if (r.l2p_to_interp >= 0) out << r.l2p_to_interp;
    out << "," << r.key_motion_cm << "," << r.seam_cm;
    for (const std::string& n : names) {
      out << ",";
      for (const auto& d : r.diagnostics)
        if (d.first == n) out << d.second;
    }
    out << "\n";
  }
  return out.str();
}

void WindowLog::write_csv(const std::string& path) const {
  std::ofstream f(path);
  f << csv();
  if (!f) throw std::runtime_error("cannot write " + path);
}

}  // namespace mf::bench
