#include "capi/src/jobs/jsonl.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <limits>
#include <optional>
#include <set>
#include <utility>


namespace motionfield::jobs {

JsonError::JsonError(int column, const std::string& message)
    : std::runtime_error("column " + std::to_string(column) + ": " + message), column_(column) {}

JsonValue JsonValue::boolean(bool b) {
  JsonValue v;
  v.type_ = Type::Bool;
  v.bool_ = b;
  return v;
}

JsonValue JsonValue::number(double d) {
  JsonValue v;
  v.type_ = Type::Number;
  v.number_ = d;
  return v;
}

JsonValue JsonValue::string(std::string s) {
  JsonValue v;
  v.type_ = Type::String;
  v.string_ = std::move(s);
  return v;
}

JsonValue JsonValue::array(std::vector<JsonValue> items) {
  JsonValue v;
  v.type_ = Type::Array;
  v.items_ = std::move(items);
  return v;
}

JsonValue JsonValue::object(std::vector<std::string> keys, std::vector<JsonValue> values) {
  if (keys.size() != values.size()) throw std::logic_error("JsonValue::object: keys and values differ in length");
  JsonValue v;
  v.type_ = Type::Object;
  v.keys_ = std::move(keys);
  v.items_ = std::move(values);
  return v;
}

namespace {
void expect_type(JsonValue::Type actual, JsonValue::Type wanted) {
  if (actual != wanted)
    throw std::logic_error(std::string("JSON value is ") + json_type_name(actual) + ", not " + json_type_name(wanted));
}
}  // namespace

bool JsonValue::as_bool() const {
  expect_type(type_, Type::Bool);
  return bool_;
}
double JsonValue::as_number() const {
  expect_type(type_, Type::Number);
  return number_;
}
const std::string& JsonValue::as_string() const {
  expect_type(type_, Type::String);
  return string_;
}
const std::vector<JsonValue>& JsonValue::as_array() const {
  expect_type(type_, Type::Array);
  return items_;
}
const std::vector<std::string>& JsonValue::keys() const {
  expect_type(type_, Type::Object);
  return keys_;
}
const std::vector<JsonValue>& JsonValue::values() const {
  expect_type(type_, Type::Object);
  return items_;
}

const JsonValue* JsonValue::find(const std::string& key) const {
  if (type_ != Type::Object) return nullptr;
  for (size_t i = 0; i < keys_.size(); ++i)
    if (keys_[i] == key) return &items_[i];
  return nullptr;
}

namespace {

void dump_string(const std::string& s, std::string& out) {
  out += '"';
  for (unsigned char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\b': out += "\\b"; break;
      case '\f': out += "\\f"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += static_cast<char>(c);
        }
    }
  }
  out += '"';
}

void dump_value(const JsonValue& v, std::string& out) {
  switch (v.type()) {
    case JsonValue::Type::Null: out += "null"; break;
    case JsonValue::Type::Bool: out += v.as_bool() ? "true" : "false"; break;
    case JsonValue::Type::Number: {
      // -0.0 as "-0.0", not to_chars' "-0": the parser reads "-0" as the
      // integer 0, and the sign would be lost on the way back.
      if (v.as_number() == 0.0 && std::signbit(v.as_number())) {
        out += "-0.0";
        break;
      }
      char buf[32];
      auto r = std::to_chars(buf, buf + sizeof buf, v.as_number());  // shortest round-trip form
      out.append(buf, r.ptr);
      break;
    }
    case JsonValue::Type::String: dump_string(v.as_string(), out); break;
    case JsonValue::Type::Array: {
      out += '[';
      const auto& items = v.as_array();
      for (size_t i = 0; i < items.size(); ++i) {
        if (i) out += ',';
        dump_value(items[i], out);
      }
      out += ']';
      break;
    }
    case JsonValue::Type::Object: {
      out += '{';
      for (size_t i = 0; i < v.keys().size(); ++i) {
        if (i) out += ',';
        dump_string(v.keys()[i], out);
        out += ':';
        dump_value(v.values()[i], out);
      }
      out += '}';
      break;
    }
  }
}

// Byte iterator over the input that publishes how far nlohmann's lexer has read,
// so that the SAX handler can place the errors it raises itself (duplicate
// keys, nesting) at a column.
class CountingIterator {
 public:
  using iterator_category = std::input_iterator_tag;
  using value_type = char;
  using difference_type = std::ptrdiff_t;
  using pointer = const char*;
  using reference = const char&;

  CountingIterator(const char* p, const char* base, size_t* consumed) : p_(p), base_(base), consumed_(consumed) {}
  reference operator*() const { return *p_; }
  CountingIterator& operator++() {
    ++p_;
    *consumed_ = static_cast<size_t>(p_ - base_);
    return *this;
  }
  CountingIterator operator++(int) {
    CountingIterator old = *this;
    ++*this;
    return old;
  }
  bool operator==(const CountingIterator& o) const { return p_ == o.p_; }
  bool operator!=(const CountingIterator& o) const { return p_ != o.p_; }

 private:
  const char* p_;
  const char* base_;
  size_t* consumed_;
};

// Builds a JsonValue from nlohmann's SAX events and adds the checks nlohmann
// leaves to its callers: duplicate keys and the depth limit.
class Builder : public nlohmann::json_sax<nlohmann::json> {
 public:
  Builder(const std::string& text, const size_t* consumed) : s_(text), consumed_(*consumed) {}

  JsonValue result;
  std::optional<JsonError> error;

  bool null() override { return add(JsonValue()); }
  bool boolean(bool b) override { return add(JsonValue::boolean(b)); }
  bool number_integer(number_integer_t n) override { return add(JsonValue::number(static_cast<double>(n))); }
  bool number_unsigned(number_unsigned_t n) override { return add(JsonValue::number(static_cast<double>(n))); }
  bool number_float(number_float_t d, const string_t&) override { return add(JsonValue::number(d)); }
  bool string(string_t& s) override { return add(JsonValue::string(std::move(s))); }
  bool binary(binary_t&) override { return fail(consumed_, "unexpected binary value"); }  // not in JSON text

  bool start_object(std::size_t) override { return open(true); }
  bool key(string_t& k) override {
    Frame& f = stack_.back();
    if (!f.seen.insert(k).second) {
      // The key's closing quote was the last character read; find its opening quote.
      size_t at = consumed_ - 1;
      while (at > 0) {
        --at;
        size_t backslashes = 0;
        while (backslashes < at && s_[at - 1 - backslashes] == '\\') ++backslashes;
        if (s_[at] == '"' && backslashes % 2 == 0) break;
      }
      return fail(at, "duplicate key \"" + k + "\"");
    }
    f.keys.push_back(std::move(k));
    return true;
  }
  bool end_object() override { return close(); }
  bool start_array(std::size_t) override { return open(false); }
  bool end_array() override { return close(); }

  bool parse_error(std::size_t position, const std::string& last_token, const nlohmann::detail::exception& e) override {
    // Overflow (exception 406) is reported after the number: point at its start.
    if (e.id == 406)
      return fail(position - std::min(position, last_token.size()), "number out of range: " + last_token);
    // e.what(): "[json.exception.parse_error.101] parse error at line 1, column 9: syntax error ..."
    std::string message = e.what();
    const size_t column = message.find(", column ");
    if (column != std::string::npos) {
      const size_t colon = message.find(": ", column);
      if (colon != std::string::npos) message.erase(0, colon + 2);
    }
    // position counts the characters read, the offending one included.
    const size_t at = std::min(position > 0 ? position - 1 : 0, s_.size());
    if (at < s_.size() && (s_[at] == '}' || s_[at] == ']')) {
      size_t k = at;
      while (k > 0 && std::strchr(" \t\r\n", s_[k - 1]) != nullptr) --k;
      if (k > 0 && s_[k - 1] == ',') message += " (trailing comma?)";
    }
    return fail(at, message);
  }

 private:
  struct Frame {
    bool object = false;
    std::vector<std::string> keys;
    std::vector<JsonValue> values;
    std::set<std::string> seen;
  };

  bool fail(size_t at, const std::string& message) {
    int column = 1;
    for (size_t i = 0; i < at && i < s_.size(); ++i)
      if ((static_cast<unsigned char>(s_[i]) & 0xC0) != 0x80) ++column;
    error.emplace(column, message);
    return false;
  }

  bool add(JsonValue v) {
    if (stack_.empty())
      result = std::move(v);
    else
      stack_.back().values.push_back(std::move(v));
    return true;
  }

  bool open(bool object) {
    if (stack_.size() >= static_cast<size_t>(kJsonMaxDepth))
      return fail(consumed_ - 1, "nesting deeper than " + std::to_string(kJsonMaxDepth) + " levels");
    stack_.emplace_back();
    stack_.back().object = object;
    return true;
  }

  bool close() {
    Frame f = std::move(stack_.back());
    stack_.pop_back();
    return add(f.object ? JsonValue::object(std::move(f.keys), std::move(f.values))
                        : JsonValue::array(std::move(f.values)));
  }

  const std::string& s_;
  const size_t& consumed_;
  std::vector<Frame> stack_;
};

std::string where(const std::string& key) { return "\"" + key + "\""; }

// "fps": a number; for a single command also its text ("nan", "inf": what JSON
// cannot hold, left for the library's own check).
double fps_value(const JsonValue& f, bool single) {
  if (single && f.is_string()) {
    const std::string& text = f.as_string();
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (!text.empty() && end == text.c_str() + text.size()) return v;
  }
  if (!f.is_number()) throw InputError(std::string("\"fps\" must be a number, not ") + json_type_name(f.type()));
  return f.as_number();
}

const JsonValue& required(const JsonValue& obj, const std::string& key, const std::string& task) {
  const JsonValue* v = obj.find(key);
  if (!v) throw InputError("missing key " + where(key) + (task.empty() ? "" : " (needed by task \"" + task + "\")"));
  return *v;
}

std::string string_value(const JsonValue& v, const std::string& key, bool allow_empty) {
  if (!v.is_string()) throw InputError(where(key) + " must be a string, not " + json_type_name(v.type()));
  if (!allow_empty && v.as_string().empty()) throw InputError(where(key) + " must not be empty");
  // A file name cannot hold a NUL: the system would silently cut it there
  // ("a.bvh\u0000.evil" would name a.bvh).
  if (v.as_string().find('\0') != std::string::npos)
    throw InputError(where(key) + " contains a NUL character (\\u0000), which no file name or value can hold");
  return v.as_string();
}

int int_value(const JsonValue& v, const std::string& what) {
  if (!v.is_number()) throw InputError(what + " must be an integer, not " + json_type_name(v.type()));
  const double d = v.as_number();
  if (d != std::floor(d) || d < std::numeric_limits<int>::min() || d > std::numeric_limits<int>::max())
    throw InputError(what + " must be an integer, not " + v.dump());
  return static_cast<int>(d);
}

std::vector<int> int_array(const JsonValue& v, const std::string& key) {
  if (!v.is_array()) throw InputError(where(key) + " must be an array of integers, not " + json_type_name(v.type()));
  std::vector<int> out;
  const auto& items = v.as_array();
  for (size_t i = 0; i < items.size(); ++i)
    out.push_back(int_value(items[i], where(key) + " item " + std::to_string(i)));
  return out;
}

// "constraints" (a file name or an inline object), "trajectory", "alternatives", "report".
void read_constraints(const JsonValue& line, BatchJob* job) {
  if (const JsonValue* c = line.find("constraints")) {
    if (c->is_object())
      job->constraints_json = c->dump();
    else if (c->is_string())
      job->constraints_file = string_value(*c, "constraints", false);
    else
      throw InputError(std::string("\"constraints\" must be a file name or an object, not ") + json_type_name(c->type()));
  }
  if (const JsonValue* t = line.find("trajectory")) job->trajectory_file = string_value(*t, "trajectory", false);
  if (const JsonValue* n = line.find("alternatives")) {
    job->alternatives = int_value(*n, "\"alternatives\"");
    if (job->alternatives < 0 || job->alternatives > 16)
      throw InputError("\"alternatives\" must be between 0 and 16, not " + n->dump());
  }
  if (const JsonValue* r = line.find("report")) job->report_file = string_value(*r, "report", false);
}

// A boolean value of `key`.
bool bool_value(const JsonValue& v, const char* key) {
  if (!v.is_bool()) throw InputError(std::string("\"") + key + "\" must be true or false, not " + json_type_name(v.type()));
  return v.as_bool();
}

// The keys of a transition: "to" (clip B), "frames", "from_frame", "to_frame", "place", "only_transition".
void read_transition_keys(const JsonValue& line, BatchJob* job) {
  job->to = string_value(required(line, "to", job->task), "to", false);
  if (const JsonValue* n = line.find("frames")) job->frames = int_value(*n, "\"frames\"");
  if (const JsonValue* i = line.find("from_frame")) job->from_frame = int_value(*i, "\"from_frame\"");
  if (const JsonValue* j = line.find("to_frame")) job->to_frame = int_value(*j, "\"to_frame\"");
  if (const JsonValue* p = line.find("place")) {
    const std::string place = string_value(*p, "place", false);
    if (place != "auto" && place != "keep")
      throw InputError("\"place\" must be \"auto\" or \"keep\", not " + p->dump());
    job->place_keep = place == "keep";
  }
  if (const JsonValue* o = line.find("only_transition")) job->only_transition = bool_value(*o, "only_transition");
}

// The keys of job->task: keyframes, gap, fps, the path of a re-navigation, constraints.
void read_task_keys(const JsonValue& line, bool single, BatchJob* job_out) {
  BatchJob& job = *job_out;
  if (job.task == "inbetween" || job.task == "fill" || job.task == "transition") {
    read_constraints(line, &job);
    if (const JsonValue* f = line.find("fallback")) job.fallback = bool_value(*f, "fallback");
  }
  if (job.task == "transition") {
    read_transition_keys(line, &job);
  } else if (job.task == "inbetween") {
    job.keyframes = int_array(required(line, "keyframes", job.task), "keyframes");
    job.has_keyframes = true;
  } else if (job.task == "fill") {
    if (const JsonValue* k = line.find("keyframes")) {
      job.keyframes = int_array(*k, "keyframes");
      job.has_keyframes = true;
    } else {
      const JsonValue& g = required(line, "gap", job.task);
      if (!g.is_array() || g.as_array().size() != 2)
        throw InputError("\"gap\" must be an array of two integers [A, B], not " +
                         (g.is_array() ? g.dump() : std::string(json_type_name(g.type()))));
      job.gap_begin = int_value(g.as_array()[0], "\"gap\" item 0");
      job.gap_end = int_value(g.as_array()[1], "\"gap\" item 1");
      job.has_gap = true;
    }
  } else if (job.task == "resample") {
    job.fps = fps_value(required(line, "fps", job.task), single);
  } else {  // renav
    const JsonValue* path = line.find("path");
    const JsonValue* polyline = line.find("polyline");
    if ((path != nullptr) == (polyline != nullptr))
      throw InputError("task \"renav\" needs exactly one of \"path\" and \"polyline\"");
    job.polyline = polyline != nullptr;
    job.path_file = string_value(job.polyline ? *polyline : *path, job.polyline ? "polyline" : "path", false);
    if (const JsonValue* f = line.find("fps")) {
      if (!f->is_number()) throw InputError(std::string("\"fps\" must be a number, not ") + json_type_name(f->type()));
      job.fps = f->as_number();
      if (!(job.fps > 0)) throw InputError("\"fps\" must be positive, not " + f->dump());
    }
    if (const JsonValue* n = line.find("frames")) {
      if (!job.polyline) throw InputError("\"frames\" goes with \"polyline\" (a \"path\" has one point per frame)");
      job.frames = int_value(*n, "\"frames\"");
    }
  }
}

}  // namespace

std::string JsonValue::dump() const {
  std::string out;
  dump_value(*this, out);
  return out;
}

JsonValue parse_json(const std::string& text) {
  size_t consumed = 0;
  Builder builder(text, &consumed);
  const char* base = text.data();
  const bool ok = nlohmann::json::sax_parse(CountingIterator(base, base, &consumed),
                                            CountingIterator(base + text.size(), base, &consumed), &builder);
  if (builder.error) throw *builder.error;
  if (!ok) throw JsonError(1, "invalid JSON");  // not reached: every failure sets an error
  return std::move(builder.result);
}

const char* json_type_name(JsonValue::Type type) {
  switch (type) {
    case JsonValue::Type::Null: return "null";
    case JsonValue::Type::Bool: return "a boolean";
    case JsonValue::Type::Number: return "a number";
    case JsonValue::Type::String: return "a string";
    case JsonValue::Type::Array: return "an array";
    case JsonValue::Type::Object: return "an object";
  }
  return "unknown";
}

BatchJob batch_job_from_json(const JsonValue& line, bool single) {
  if (!line.is_object()) throw InputError(std::string("a job must be a JSON object, not ") + json_type_name(line.type()));
  BatchJob job;
  if (const JsonValue* id = line.find("id")) job.id = id->is_string() ? id->as_string() : id->dump();
  job.task = string_value(required(line, "task", ""), "task", false);
  const bool export_only = single && job.task == "export";
  if (job.task != "inbetween" && job.task != "fill" && job.task != "resample" && job.task != "renav" &&
      job.task != "transition" && !export_only)
    throw InputError("unknown task \"" + job.task +
                     "\" (expected \"inbetween\", \"fill\", \"resample\", \"renav\" or \"transition\")");
  job.in = string_value(required(line, "in", job.task), "in", false);
  job.out = string_value(required(line, "out", job.task), "out", false);
  if (const JsonValue* a = line.find("animation")) {
    if (a->is_string()) {
      job.animation = string_value(*a, "animation", false);
    } else {
      job.animation_index = int_value(*a, "\"animation\"");
      if (job.animation_index < 0)
        throw InputError("\"animation\" must be a name or an index from 0, not " + a->dump());
    }
  }
  if (export_only) return job;
  if (const JsonValue* m = line.find("method")) job.method = string_value(*m, "method", false);
  if (const JsonValue* n = line.find("max_iterations")) {
    job.max_iterations = int_value(*n, "\"max_iterations\"");
    if (job.max_iterations < 0 || job.max_iterations > 100000)
      throw InputError("\"max_iterations\" must be between 0 and 100000, not " + n->dump());
  }
  if (const JsonValue* r = line.find("rig_map")) job.rig_map = string_value(*r, "rig_map", false);
  if (const JsonValue* u = line.find("units")) {
    if (!u->is_number()) {
      if (!u->is_string())
        throw InputError(std::string("\"units\" must be a unit name or a number, not ") + json_type_name(u->type()));
      job.units = string_value(*u, "units", false);
    } else if (u->as_number() > 0) {
      job.units = u->dump();
    } else {
      throw InputError("\"units\" must be positive, not " + u->dump());
    }
  }

  read_task_keys(line, single, &job);
  return job;
}

}  // namespace motionfield::jobs
