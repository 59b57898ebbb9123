// The transformer in-betweeners' kinds and hyperparameters: plain structs,
// torch-free, shared by the libtorch networks (two_stage.h, citl.h,
// keyframe_net.h, which document the architectures and the defaults) and the
// Eigen runtime (prior/runtime/inbetween_runtime.h), so both read a model
// file's hyperparameters by the same rules.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "prior/inbetween/transformer_sizes.h"

namespace mf {

/// The model file's kind strings of the product's in-betweeners.
constexpr char kTwoStageKind[] = "twostage";
constexpr char kCitlKind[] = "citl";
constexpr char kKeyframeKind[] = "keyframe";

/// Reads a kind's hyperparameters (make_inbetweener's map) into its config,
/// collecting every problem so that one InputError names them all:
///   HyperparameterReader r("CITL", values);
///   r.integer("width", 8, 2048, &c.width);
///   r.check(c.width % c.heads == 0, "heads must divide width");
///   r.finish();  // throws on any problem or on a key no call read
class HyperparameterReader {
 public:
  HyperparameterReader(std::string model_name, const std::map<std::string, double>& values);
  /// values[key], when present, must be an integer in [lo, hi].
  void integer(const std::string& key, int lo, int hi, int* out);
  /// values[key], when present, must be finite and in (0, hi].
  void positive(const std::string& key, double hi, double* out);
  /// Records `message` as a problem unless `ok`.
  void check(bool ok, const std::string& message);
  /// Throws mf::InputError listing the problems and the unknown keys.
  void finish() const;

 private:
  std::string name_;
  std::map<std::string, double> unread_;
  std::vector<std::string> known_;
  std::string problems_;
};

/// Every in-betweener's file names its "window" and "fps" (positive, finite):
/// InputError "<source>: invalid hyperparameters: ..." otherwise.
void check_window_and_fps(const std::map<std::string, double>& hyperparameters, const std::string& source);

/// The two-stage transformer's hyperparameters (two_stage.h).
struct TwoStageConfig {
  int width = 64;
  int layers = 2;
  int heads = 4;
  int ffn = 128;
  int window = 128;
  double fps = 30.0;
  int interp_input = 0;

  /// Named fields, for the model file ("interp_input" only when set: files
  /// of the original design do not have it).
  std::map<std::string, double> to_map() const;
  blocks::TrunkSize trunk() const { return {width, layers, heads, ffn, window}; }
};
/// Missing keys take the defaults; unknown keys or invalid values throw InputError.
TwoStageConfig parse_two_stage_config(const std::map<std::string, double>& values);

/// CITL's hyperparameters (citl.h).
struct CitlConfig {
  int width = 64;
  int layers = 2;
  int heads = 4;
  int ffn = 256;
  int time_dim = 16;
  int window = 128;
  double fps = 30.0;

  std::map<std::string, double> to_map() const;
};
/// Missing keys take the defaults; unknown keys or invalid values throw InputError.
CitlConfig parse_citl_config(const std::map<std::string, double>& values);

/// KeyframeNet + RefineNet's hyperparameters (keyframe_net.h).
struct KeyframeConfig {
  int width = 64;
  int layers = 2;
  int heads = 4;
  int ffn = 128;
  int window = 256;
  double fps = 30.0;
  int min_spacing = 5;
  int max_spacing = 30;

  std::map<std::string, double> to_map() const;
  blocks::TrunkSize trunk() const { return {width, layers, heads, ffn, window}; }
};
/// Missing keys take the defaults; unknown keys or invalid values throw InputError.
KeyframeConfig parse_keyframe_config(const std::map<std::string, double>& values);

}  // namespace mf
