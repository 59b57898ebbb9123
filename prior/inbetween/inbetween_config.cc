#include "prior/inbetween/inbetween_config.h"

#include <cmath>
#include <sstream>
#include <utility>

#include "prior/motion/errors.h"

namespace mf {

HyperparameterReader::HyperparameterReader(std::string model_name, const std::map<std::string, double>& values)
    : name_(std::move(model_name)), unread_(values) {}

void HyperparameterReader::integer(const std::string& key, int lo, int hi, int* out) {
  known_.push_back(key);
  auto it = unread_.find(key);
  if (it == unread_.end()) return;
  const double v = it->second;
  unread_.erase(it);
  if (!std::isfinite(v) || v != std::floor(v) || v < lo || v > hi) {
    std::ostringstream e;
    e << key << " must be an integer in [" << lo << ", " << hi << "] (got " << v << "); ";
    problems_ += e.str();
    return;
  }
  *out = static_cast<int>(v);
}

void HyperparameterReader::positive(const std::string& key, double hi, double* out) {
  known_.push_back(key);
  auto it = unread_.find(key);
  if (it == unread_.end()) return;
  const double v = it->second;
  unread_.erase(it);
  if (!std::isfinite(v) || !(v > 0) || v > hi) {
    std::ostringstream e;
    e << key << " must be in (0, " << hi << "] (got " << v << "); ";
    problems_ += e.str();
    return;
  }
  *out = v;
}

void HyperparameterReader::check(bool ok, const std::string& message) {
  if (!ok) problems_ += message + "; ";
}

void HyperparameterReader::finish() const {
  std::string message = problems_;
  for (const auto& [key, v] : unread_) {
    std::string list;
    for (const std::string& k : known_) list += (list.empty() ? "" : ", ") + k;
    message += "unknown hyperparameter '" + key + "' (" + name_ + " takes " + list + "); ";
  }
  if (!message.empty()) {
    throw InputError("invalid " + name_ + " hyperparameters: " + message.substr(0, message.size() - 2));
  }
}

namespace {

// The keys of the kinds built on blocks::TrunkSize (two-stage, keyframe), in
// the order their messages list them.
void read_trunk_keys(HyperparameterReader& r, int* width, int* layers, int* heads, int* ffn, int* window,
                     double* fps) {
  r.integer("width", 4, 4096, width);
  r.integer("layers", 1, 64, layers);
  r.integer("heads", 1, 64, heads);
  r.integer("ffn", 1, 16384, ffn);
  r.integer("window", 2, 4096, window);
  r.positive("fps", 1000, fps);
}

}  // namespace

void check_window_and_fps(const std::map<std::string, double>& hyperparameters, const std::string& source) {
  for (const char* key : {"window", "fps"}) {
    auto it = hyperparameters.find(key);
    if (it == hyperparameters.end() || !(it->second > 0) || !std::isfinite(it->second)) {
      throw InputError(source + ": invalid hyperparameters: '" + key + "' missing or not positive");
    }
  }
}

std::map<std::string, double> TwoStageConfig::to_map() const {
  std::map<std::string, double> m{{"width", width}, {"layers", layers}, {"heads", heads},
                                  {"ffn", ffn},     {"window", window}, {"fps", fps}};
  if (interp_input) m["interp_input"] = interp_input;  // absent in files of the original design
  return m;
}

TwoStageConfig parse_two_stage_config(const std::map<std::string, double>& values) {
  TwoStageConfig c;
  HyperparameterReader r("twostage", values);
  read_trunk_keys(r, &c.width, &c.layers, &c.heads, &c.ffn, &c.window, &c.fps);
  r.integer("interp_input", 0, 1, &c.interp_input);
  r.check(c.width % c.heads == 0,
          "heads (" + std::to_string(c.heads) + ") must divide width (" + std::to_string(c.width) + ")");
  r.finish();
  return c;
}

std::map<std::string, double> CitlConfig::to_map() const {
  return {{"width", width},       {"layers", layers}, {"heads", heads}, {"ffn", ffn},
          {"time_dim", time_dim}, {"window", window}, {"fps", fps}};
}

CitlConfig parse_citl_config(const std::map<std::string, double>& values) {
  CitlConfig c;
  HyperparameterReader r("CITL", values);
  r.integer("width", 8, 2048, &c.width);
  r.integer("layers", 1, 32, &c.layers);
  r.integer("heads", 1, 64, &c.heads);
  r.integer("ffn", 1, 16384, &c.ffn);
  r.integer("time_dim", 2, 256, &c.time_dim);
  r.integer("window", 2, 4096, &c.window);
  r.positive("fps", 1000, &c.fps);
  r.check(c.width % c.heads == 0,
          "heads (" + std::to_string(c.heads) + ") must divide width (" + std::to_string(c.width) + ")");
  r.check(c.time_dim % 2 == 0, "time_dim must be even (got " + std::to_string(c.time_dim) + ")");
  r.check(c.time_dim < c.width, "time_dim must be smaller than width");
  r.finish();
  return c;
}

std::map<std::string, double> KeyframeConfig::to_map() const {
  return {{"width", width}, {"layers", layers}, {"heads", heads},
          {"ffn", ffn},     {"window", window}, {"fps", fps},
          {"min_spacing", min_spacing}, {"max_spacing", max_spacing}};
}

KeyframeConfig parse_keyframe_config(const std::map<std::string, double>& values) {
  KeyframeConfig c;
  HyperparameterReader r("keyframe", values);
  read_trunk_keys(r, &c.width, &c.layers, &c.heads, &c.ffn, &c.window, &c.fps);
  r.integer("min_spacing", 1, 4096, &c.min_spacing);
  r.integer("max_spacing", 2, 4096, &c.max_spacing);
  r.check(c.width % c.heads == 0,
          "heads (" + std::to_string(c.heads) + ") must divide width (" + std::to_string(c.width) + ")");
  r.check(c.max_spacing >= 2 * c.min_spacing, "max_spacing (" + std::to_string(c.max_spacing) +
                                                  ") must be at least twice min_spacing (" +
                                                  std::to_string(c.min_spacing) + ")");
  r.finish();
  return c;
}

}  // namespace mf
