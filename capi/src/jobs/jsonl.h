// The JSON lines of batch jobs (`motionfield batch`, mf_job_runner): strict JSON (RFC 8259) parsed by
// nlohmann-json's SAX parser into a small value type, and the translation of
// one parsed line into a batch job.
//
// parse_json accepts exactly one JSON value surrounded by optional whitespace
// and rejects, with nlohmann's own checks, trailing commas, comments, single
// quotes, unescaped control characters in strings, invalid UTF-8, lone
// surrogates, numbers that overflow a double and anything after the value; it
// adds two checks of its own: duplicate object keys and nesting deeper than
// kJsonMaxDepth (the parser is iterative, so deep input cannot overflow the
// stack either way). "\u0000" is accepted and decodes to a NUL character.
// Errors are JsonError, whose message starts with "column N: " (1-based,
// counted in characters of the UTF-8 input): for a syntax error the column
// where it was detected (one past a truncated token) and nlohmann's
// description, which quotes what was last read; for a duplicate key, the
// key; for too deep nesting, the bracket; for an overflowing number, its start.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "motionfield.hpp"

namespace motionfield::jobs {

constexpr int kJsonMaxDepth = 64;

class JsonError : public std::runtime_error {
 public:
  JsonError(int column, const std::string& message);
  /// 1-based character column of the offending input.
  int column() const { return column_; }

 private:
  int column_;
};

/// One JSON value. Objects keep their members in input order.
class JsonValue {
 public:
  enum class Type { Null, Bool, Number, String, Array, Object };

  JsonValue() = default;  ///< null
  static JsonValue boolean(bool b);
  static JsonValue number(double d);
  static JsonValue string(std::string s);
  static JsonValue array(std::vector<JsonValue> items);
  /// `keys` and `values` have the same length; keys must be unique.
  static JsonValue object(std::vector<std::string> keys, std::vector<JsonValue> values);

  Type type() const { return type_; }
  bool is_null() const { return type_ == Type::Null; }
  bool is_bool() const { return type_ == Type::Bool; }
  bool is_number() const { return type_ == Type::Number; }
  bool is_string() const { return type_ == Type::String; }
  bool is_array() const { return type_ == Type::Array; }
  bool is_object() const { return type_ == Type::Object; }

  /// Accessors; each throws std::logic_error if the value has another type.
  bool as_bool() const;
  double as_number() const;
  const std::string& as_string() const;
  const std::vector<JsonValue>& as_array() const;
  const std::vector<std::string>& keys() const;     ///< object member names, in order
  const std::vector<JsonValue>& values() const;     ///< object member values, in order

  /// Member `key` of an object, or nullptr if absent (or if this is not an object).
  const JsonValue* find(const std::string& key) const;

  /// Compact JSON text of the value (strings escaped, numbers with up to 17
  /// significant digits): for messages.
  std::string dump() const;

 private:
  Type type_ = Type::Null;
  bool bool_ = false;
  double number_ = 0.0;
  std::string string_;
  std::vector<JsonValue> items_;  // array items, or object values
  std::vector<std::string> keys_;
};

/// Parses one JSON text. Throws JsonError.
JsonValue parse_json(const std::string& text);

/// Name of a JSON type for messages: "null", "a boolean", "a number", ...
const char* json_type_name(JsonValue::Type type);

/// One job of `motionfield batch`: {"task": "inbetween" | "fill" | "resample" |
/// "renav" | "transition", "in": path, "out": path, "keyframes": [int...], "gap": [A, B],
/// "fps": F, "method": name}; re-navigation takes exactly one of "path" (a CSV
/// of x,z per output frame) and "polyline" (a CSV of vertices, with an
/// optional "frames": N), and an optional "fps". Every task takes an optional
/// "rig_map" (a JSON map file) and "units" (a unit name, "auto", or metres per
/// unit as a number or a string) and, for glTF and FBX inputs, "animation" (a
/// name, or an index from 0). inbetween and fill also take "constraints"
/// (a constraints file, or the same JSON inline as an object), "trajectory"
/// (a trajectory CSV file, merged into the constraints), "alternatives"
/// and "report" (a file for the constraint report). A transition takes "to"
/// (clip B; "in" is clip A), optional "frames" (N; 0 = automatic),
/// "from_frame", "to_frame", "place" ("auto" or "keep"), "only_transition"
/// (a boolean) and the constraint keys of fill. inbetween, fill and
/// transition take "fallback" (a boolean; false: mf_task_options.no_fallback).
/// Only the keys the task needs
/// are read and type-checked; any other key ("id", a frame count, the input's
/// fps, ...) is ignored, so callers can annotate jobs.
struct BatchJob {
  std::string task;    ///< "inbetween", "fill", "resample", "renav" or "transition"
  std::string in, out; ///< paths as given (relative to the current directory)
  std::string method;  ///< empty: the default method
  int max_iterations = 0;  ///< iteration budget of iterative methods (mf_task_options); 0: each method's own
  bool fallback = true;    ///< "fallback": false keeps the latent solvers' result where it misses the keys
  std::string id;      ///< the job's "id" for messages (JSON text; strings unquoted), empty if none
  bool has_keyframes = false;
  std::vector<int> keyframes;  ///< inbetween: required; fill: optional and then authoritative
  bool has_gap = false;
  int gap_begin = 0, gap_end = 0;  ///< fill: frames gap_begin..gap_end-1 are unknown
  double fps = 0.0;                ///< resample: the target fps; renav: the output's (0 = the reference's)
  std::string path_file;           ///< renav: the CSV of the path or of the polyline's vertices
  bool polyline = false;           ///< renav: path_file holds a polyline's vertices
  int frames = 0;                  ///< renav with a polyline: the output's frame count (0 = from the speed);
                                   ///< transition: the generated frames (0 = automatic)
  std::string to;                  ///< transition: clip B (the file); "in" is clip A
  int from_frame = -1;             ///< transition: A's last kept frame (negative: from the end)
  int to_frame = 0;                ///< transition: B's first kept frame (negative: from the end)
  bool place_keep = false;         ///< transition: "place": "keep" (false: "auto")
  bool only_transition = false;    ///< transition: only the generated frames
  std::string rig_map;             ///< a rig map file; empty: the command line's (--rig-map)
  std::string units;               ///< "auto", a unit name or metres per unit as text; empty: the command line's
  std::string animation;           ///< glTF and FBX inputs: the animation's name; empty: by index
  int animation_index = 0;         ///< glTF and FBX inputs: the animation's index (when no name)
  // inbetween, fill and transition: constraints beyond whole-pose keys (docs/CONSTRAINTS.md)
  std::string constraints_file;    ///< a constraints file; empty: none
  std::string constraints_json;    ///< inline constraints (JSON text); empty: none
  std::string trajectory_file;     ///< a trajectory CSV (merged into the constraints); empty: none
  int alternatives = 0;            ///< more solutions, written to OUT_1.bvh .. OUT_N.bvh
  std::string report_file;         ///< where the constraint report goes (JSON); empty: nowhere

  /// True when the job goes through mf_solve (constraints, alternatives or a report).
  bool constrained() const {
    return !constraints_file.empty() || !constraints_json.empty() || !trajectory_file.empty() || alternatives > 0 ||
           !report_file.empty();
  }
};

/// Reads a job from one parsed line. Throws InputError with a message naming
/// the key when the value is not an object, "task" is missing or unknown, or a
/// key the task needs is missing or has the wrong type ("in" and "out" non-empty
/// strings; "keyframes" an array of integers; "gap" an array of two integers;
/// "fps" a number; "max_iterations" an integer in 0..100000; "method",
/// "path", "polyline" and "rig_map" strings;
/// "frames" an integer; "units" a string or a positive number; "animation" a
/// string or an integer from 0; for inbetween, fill
/// and transition "constraints" a file name or an inline object, "trajectory" a file
/// name, "alternatives" an
/// integer in 0..16, "report" a file name; for transition "to" a non-empty
/// string, "from_frame" and "to_frame" integers, "place" "auto" or "keep",
/// "only_transition" a boolean; "fallback" a boolean; no string
/// may contain a NUL, "\u0000", which would cut a file name). Range checks
/// (keyframes within the clip, fps positive, ...) are the library's, once the
/// input is read. `single` (a single command of the CLI): the task "export"
/// ("in", "out" and "animation" only) is accepted too, and a resample's "fps" may be the
/// text of a number ("nan", which JSON cannot hold, for the library's check).
BatchJob batch_job_from_json(const JsonValue& line, bool single = false);

}  // namespace motionfield::jobs
