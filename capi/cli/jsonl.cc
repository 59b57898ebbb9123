#include "capi/cli/jsonl.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <utility>

#include "prior/motion/errors.h"

namespace mf::cli {

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

// Recursive-descent parser over the raw bytes; positions are byte offsets,
// converted to character columns only when an error is reported.
class Parser {
 public:
  explicit Parser(const std::string& text) : s_(text) {}

  JsonValue parse_document() {
    skip_ws();
    JsonValue v = parse_value(0);
    skip_ws();
    if (pos_ < s_.size()) fail(pos_, "unexpected " + describe(pos_) + " after the JSON value");
    return v;
  }

 private:
  [[noreturn]] void fail(size_t at, const std::string& message) const {
    int column = 1;
    for (size_t i = 0; i < at && i < s_.size(); ++i)
      if ((static_cast<unsigned char>(s_[i]) & 0xC0) != 0x80) ++column;
    throw JsonError(column, message);
  }

  std::string describe(size_t at) const {
    if (at >= s_.size()) return "end of input";
    const unsigned char c = static_cast<unsigned char>(s_[at]);
    if (c < 0x20 || c >= 0x7F) {
      char buf[16];
      std::snprintf(buf, sizeof buf, "byte 0x%02X", c);
      return buf;
    }
    return std::string("character '") + static_cast<char>(c) + "'";
  }

  void skip_ws() {
    while (pos_ < s_.size() && (s_[pos_] == ' ' || s_[pos_] == '\t' || s_[pos_] == '\n' || s_[pos_] == '\r')) ++pos_;
  }

  bool at_end() const { return pos_ >= s_.size(); }

  JsonValue parse_value(int depth) {
    if (at_end()) fail(pos_, "expected a JSON value, found end of input");
    switch (s_[pos_]) {
      case '{': return parse_object(depth + 1);
      case '[': return parse_array(depth + 1);
      case '"': return JsonValue::string(parse_string());
      case 't': return parse_literal("true", JsonValue::boolean(true));
      case 'f': return parse_literal("false", JsonValue::boolean(false));
      case 'n': return parse_literal("null", JsonValue());
      default:
        if (s_[pos_] == '-' || (s_[pos_] >= '0' && s_[pos_] <= '9')) return parse_number();
        fail(pos_, "expected a JSON value, found " + describe(pos_));
    }
  }

  JsonValue parse_literal(const char* word, JsonValue value) {
    const std::string w(word);
    if (s_.compare(pos_, w.size(), w) != 0) fail(pos_, "invalid literal (expected " + w + ")");
    pos_ += w.size();
    // "trueX" must not parse as true followed by garbage at the same token.
    if (!at_end() && (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_'))
      fail(pos_, "invalid literal (expected " + w + ")");
    return value;
  }

  JsonValue parse_object(int depth) {
    if (depth > kJsonMaxDepth) fail(pos_, "nesting deeper than " + std::to_string(kJsonMaxDepth) + " levels");
    ++pos_;  // '{'
    std::vector<std::string> keys;
    std::vector<JsonValue> values;
    std::set<std::string> seen;
    skip_ws();
    if (!at_end() && s_[pos_] == '}') {
      ++pos_;
      return JsonValue::object({}, {});
    }
    while (true) {
      skip_ws();
      if (!at_end() && s_[pos_] == '}' && !keys.empty()) fail(pos_, "expected a string key, found '}' (trailing comma?)");
      if (at_end() || s_[pos_] != '"') fail(pos_, "expected a string key, found " + describe(pos_));
      const size_t key_pos = pos_;
      std::string key = parse_string();
      if (!seen.insert(key).second) fail(key_pos, "duplicate key \"" + key + "\"");
      skip_ws();
      if (at_end() || s_[pos_] != ':') fail(pos_, "expected ':' after an object key, found " + describe(pos_));
      ++pos_;
      skip_ws();
      values.push_back(parse_value(depth));
      keys.push_back(std::move(key));
      skip_ws();
      if (at_end()) fail(pos_, "expected ',' or '}' in an object, found end of input");
      if (s_[pos_] == ',') {
        ++pos_;
        continue;
      }
      if (s_[pos_] == '}') {
        ++pos_;
        return JsonValue::object(std::move(keys), std::move(values));
      }
      fail(pos_, "expected ',' or '}' in an object, found " + describe(pos_));
    }
  }

  JsonValue parse_array(int depth) {
    if (depth > kJsonMaxDepth) fail(pos_, "nesting deeper than " + std::to_string(kJsonMaxDepth) + " levels");
    ++pos_;  // '['
    std::vector<JsonValue> items;
    skip_ws();
    if (!at_end() && s_[pos_] == ']') {
      ++pos_;
      return JsonValue::array({});
    }
    while (true) {
      skip_ws();
      if (!at_end() && s_[pos_] == ']') fail(pos_, "expected a JSON value, found ']' (trailing comma?)");
      items.push_back(parse_value(depth));
      skip_ws();
      if (at_end()) fail(pos_, "expected ',' or ']' in an array, found end of input");
      if (s_[pos_] == ',') {
        ++pos_;
        continue;
      }
      if (s_[pos_] == ']') {
        ++pos_;
        return JsonValue::array(std::move(items));
      }
      fail(pos_, "expected ',' or ']' in an array, found " + describe(pos_));
    }
  }

  static int hex_digit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  }

  // Reads the 4 hex digits of a \u escape whose 'u' is at pos_ - 1.
  unsigned read_hex4(size_t escape_pos) {
    if (pos_ + 4 > s_.size()) fail(escape_pos, "truncated \\u escape (expected four hex digits)");
    unsigned v = 0;
    for (int i = 0; i < 4; ++i) {
      const int d = hex_digit(s_[pos_ + i]);
      if (d < 0) fail(pos_ + i, "invalid hex digit in \\u escape: " + describe(pos_ + i));
      v = v * 16 + static_cast<unsigned>(d);
    }
    pos_ += 4;
    return v;
  }

  static void append_utf8(unsigned cp, std::string& out) {
    if (cp < 0x80) {
      out += static_cast<char>(cp);
    } else if (cp < 0x800) {
      out += static_cast<char>(0xC0 | (cp >> 6));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
      out += static_cast<char>(0xE0 | (cp >> 12));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
      out += static_cast<char>(0xF0 | (cp >> 18));
      out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
      out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      out += static_cast<char>(0x80 | (cp & 0x3F));
    }
  }

  // Validates one UTF-8 sequence starting at pos_ (a byte >= 0x80) and appends it.
  void copy_utf8(std::string& out) {
    const size_t start = pos_;
    const unsigned char c = static_cast<unsigned char>(s_[pos_]);
    int len = 0;
    unsigned cp = 0, min = 0;
    if (c >= 0xC2 && c <= 0xDF) {
      len = 2, cp = c & 0x1F, min = 0x80;
    } else if (c >= 0xE0 && c <= 0xEF) {
      len = 3, cp = c & 0x0F, min = 0x800;
    } else if (c >= 0xF0 && c <= 0xF4) {
      len = 4, cp = c & 0x07, min = 0x10000;
    } else {
      fail(start, "invalid UTF-8 in string");
    }
    if (start + len > s_.size()) fail(start, "truncated UTF-8 sequence in string");
    for (int i = 1; i < len; ++i) {
      const unsigned char cc = static_cast<unsigned char>(s_[start + i]);
      if ((cc & 0xC0) != 0x80) fail(start, "invalid UTF-8 in string");
      cp = (cp << 6) | (cc & 0x3F);
    }
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) fail(start, "invalid UTF-8 in string");
    out.append(s_, start, static_cast<size_t>(len));
    pos_ = start + len;
  }

  std::string parse_string() {
    const size_t open = pos_;
    ++pos_;  // opening quote
    std::string out;
    while (true) {
      if (at_end()) fail(open, "unterminated string");
      const unsigned char c = static_cast<unsigned char>(s_[pos_]);
      if (c == '"') {
        ++pos_;
        return out;
      }
      if (c < 0x20) fail(pos_, "unescaped control character (" + describe(pos_) + ") in string");
      if (c >= 0x80) {
        copy_utf8(out);
        continue;
      }
      if (c != '\\') {
        out += static_cast<char>(c);
        ++pos_;
        continue;
      }
      const size_t escape_pos = pos_;
      ++pos_;
      if (at_end()) fail(open, "unterminated string");
      const char e = s_[pos_++];
      switch (e) {
        case '"': out += '"'; break;
        case '\\': out += '\\'; break;
        case '/': out += '/'; break;
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'n': out += '\n'; break;
        case 'r': out += '\r'; break;
        case 't': out += '\t'; break;
        case 'u': {
          unsigned cp = read_hex4(escape_pos);
          if (cp >= 0xDC00 && cp <= 0xDFFF) fail(escape_pos, "lone low surrogate in \\u escape");
          if (cp >= 0xD800 && cp <= 0xDBFF) {
            if (s_.compare(pos_, 2, "\\u") != 0) fail(escape_pos, "high surrogate not followed by a \\u low surrogate");
            const size_t low_pos = pos_;
            pos_ += 2;
            const unsigned low = read_hex4(low_pos);
            if (low < 0xDC00 || low > 0xDFFF) fail(low_pos, "high surrogate not followed by a low surrogate");
            cp = 0x10000 + ((cp - 0xD800) << 10) + (low - 0xDC00);
          }
          append_utf8(cp, out);
          break;
        }
        default: fail(escape_pos, std::string("invalid escape '\\") + e + "' in string");
      }
    }
  }

  JsonValue parse_number() {
    const size_t start = pos_;
    auto digit = [&](size_t i) { return i < s_.size() && s_[i] >= '0' && s_[i] <= '9'; };
    size_t i = pos_;
    if (s_[i] == '-') ++i;
    if (!digit(i)) fail(i, "expected a digit in number, found " + describe(i));
    if (s_[i] == '0') {
      ++i;
      if (digit(i)) fail(i, "leading zeros are not allowed in numbers");
    } else {
      while (digit(i)) ++i;
    }
    if (i < s_.size() && s_[i] == '.') {
      ++i;
      if (!digit(i)) fail(i, "expected a digit after the decimal point, found " + describe(i));
      while (digit(i)) ++i;
    }
    if (i < s_.size() && (s_[i] == 'e' || s_[i] == 'E')) {
      ++i;
      if (i < s_.size() && (s_[i] == '+' || s_[i] == '-')) ++i;
      if (!digit(i)) fail(i, "expected a digit in the exponent, found " + describe(i));
      while (digit(i)) ++i;
    }
    double value = 0.0;
    const auto r = std::from_chars(s_.data() + start, s_.data() + i, value);
    if (r.ec == std::errc::result_out_of_range) {
      // Underflow to zero is harmless; overflow is not representable.
      if (decimal_magnitude(start, i) > 0) fail(start, "number out of range");
      value = 0.0;
    } else if (r.ec != std::errc() || r.ptr != s_.data() + i) {
      fail(start, "invalid number");
    }
    pos_ = i;
    return JsonValue::number(value);
  }

  // Power of ten of the leading significant digit of the number in [begin, end)
  // (whose syntax is already checked), e.g. 2 for 123.4, -3 for 0.00123e0.
  long decimal_magnitude(size_t begin, size_t end) const {
    size_t e = begin;
    while (e < end && s_[e] != 'e' && s_[e] != 'E') ++e;
    long exponent = 0;
    if (e < end) {
      size_t k = e + 1;
      const bool negative = s_[k] == '-';
      if (s_[k] == '-' || s_[k] == '+') ++k;
      for (; k < end; ++k) exponent = std::min(exponent * 10 + (s_[k] - '0'), 1L << 40);
      if (negative) exponent = -exponent;
    }
    long position = 0;  // power of ten of the digit being scanned
    size_t k = begin;
    if (s_[k] == '-') ++k;
    size_t int_digits = 0;
    while (k < e && s_[k] != '.') ++int_digits, ++k;
    position = static_cast<long>(int_digits) - 1;
    for (k = begin; k < e; ++k) {
      if (s_[k] == '-' || s_[k] == '.') continue;
      if (s_[k] != '0') return position + exponent;
      --position;
    }
    return std::numeric_limits<long>::min() / 2;  // zero
  }

  const std::string& s_;
  size_t pos_ = 0;
};

std::string where(const std::string& key) { return "\"" + key + "\""; }

const JsonValue& required(const JsonValue& obj, const std::string& key, const std::string& task) {
  const JsonValue* v = obj.find(key);
  if (!v) throw InputError("missing key " + where(key) + (task.empty() ? "" : " (needed by task \"" + task + "\")"));
  return *v;
}

std::string string_value(const JsonValue& v, const std::string& key, bool allow_empty) {
  if (!v.is_string()) throw InputError(where(key) + " must be a string, not " + json_type_name(v.type()));
  if (!allow_empty && v.as_string().empty()) throw InputError(where(key) + " must not be empty");
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

}  // namespace

std::string JsonValue::dump() const {
  std::string out;
  dump_value(*this, out);
  return out;
}

JsonValue parse_json(const std::string& text) { return Parser(text).parse_document(); }

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

BatchJob batch_job_from_json(const JsonValue& line) {
  if (!line.is_object()) throw InputError(std::string("a job must be a JSON object, not ") + json_type_name(line.type()));
  BatchJob job;
  if (const JsonValue* id = line.find("id")) job.id = id->is_string() ? id->as_string() : id->dump();
  job.task = string_value(required(line, "task", ""), "task", false);
  if (job.task != "inbetween" && job.task != "fill" && job.task != "resample" && job.task != "renav")
    throw InputError("unknown task \"" + job.task +
                     "\" (expected \"inbetween\", \"fill\", \"resample\" or \"renav\")");
  job.in = string_value(required(line, "in", job.task), "in", false);
  job.out = string_value(required(line, "out", job.task), "out", false);
  if (const JsonValue* m = line.find("method")) job.method = string_value(*m, "method", false);
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

  if (job.task == "inbetween") {
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
    const JsonValue& f = required(line, "fps", job.task);
    if (!f.is_number()) throw InputError(std::string("\"fps\" must be a number, not ") + json_type_name(f.type()));
    job.fps = f.as_number();
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
  return job;
}

}  // namespace mf::cli
