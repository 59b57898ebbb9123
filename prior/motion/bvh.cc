#include "prior/motion/bvh.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <sstream>
#include <string_view>
#include <system_error>
#include <unordered_set>

#include "prior/util/binary_io.h"
#include "prior/util/file_writer.h"

namespace mf {
namespace {

// ---------------------------------------------------------------------------
// Tokenizer

struct Token {
  std::string_view text;  // empty at end of input
  int line = 0;
  bool eof() const { return text.empty(); }
};

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }
bool is_brace(char c) { return c == '{' || c == '}'; }

// Quotes a token for an error message, shortened so hostile input cannot make
// messages huge.
std::string quote_token(std::string_view s) {
  constexpr size_t kMax = 40;
  if (s.size() > kMax) return "'" + std::string(s.substr(0, kMax)) + "...'";
  return "'" + std::string(s) + "'";
}

class Lexer {
 public:
  Lexer(const std::string& text, const std::string& source) : text_(text), source_(source) {
    if (text_.substr(0, 3) == "\xEF\xBB\xBF") pos_ = 3;
  }

  Token next() {
    Token t = peek();
    pos_ = peek_end_;
    line_ = t.line;
    has_peeked_ = false;
    return t;
  }

  Token peek() {
    if (!has_peeked_) {
      peeked_ = scan(pos_, line_, &peek_end_);
      has_peeked_ = true;
    }
    return peeked_;
  }

  /// Bytes not consumed yet.
  size_t remaining() const { return text_.size() - pos_; }
  int line() const { return line_; }

  [[noreturn]] void fail(int line, const std::string& message) const {
    throw BvhError(source_ + ":" + std::to_string(line) + ": " + message);
  }

 private:
  Token scan(size_t pos, int line, size_t* end) const {
    while (pos < text_.size() && is_space(text_[pos])) {
      if (text_[pos] == '\n') ++line;
      ++pos;
    }
    if (pos == text_.size()) {
      // Report end of input on the last line that has content, not on the empty
      // line after a final newline.
      *end = pos;
      const bool trailing_newline = !text_.empty() && text_.back() == '\n';
      return Token{std::string_view(), trailing_newline && line > 1 ? line - 1 : line};
    }
    const size_t start = pos;
    if (is_brace(text_[pos])) {
      ++pos;
    } else {
      while (pos < text_.size() && !is_space(text_[pos]) && !is_brace(text_[pos])) ++pos;
    }
    *end = pos;
    return Token{text_.substr(start, pos - start), line};
  }

  std::string_view text_;
  std::string source_;
  size_t pos_ = 0;
  int line_ = 1;
  bool has_peeked_ = false;
  Token peeked_;
  size_t peek_end_ = 0;
};

bool has_negative_exponent(std::string_view s) {
  return s.find("e-") != std::string_view::npos || s.find("E-") != std::string_view::npos;
}

// ---------------------------------------------------------------------------
// Parser

const BvhChannel kAllChannels[] = {BvhChannel::Xposition, BvhChannel::Yposition, BvhChannel::Zposition,
                                   BvhChannel::Xrotation, BvhChannel::Yrotation, BvhChannel::Zrotation};

bool equals_ignore_case(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
  return true;
}

bool channel_from_name(std::string_view name, BvhChannel* out) {
  for (BvhChannel c : kAllChannels) {
    if (equals_ignore_case(name, to_string(c))) {
      *out = c;
      return true;
    }
  }
  return false;
}

bool is_hierarchy_keyword(std::string_view s) {
  return s == "{" || s == "}" || s == "OFFSET" || s == "CHANNELS" || s == "JOINT" || s == "End" || s == "MOTION";
}

class Parser {
 public:
  Parser(const std::string& text, const std::string& source) : lex_(text, source) {}

  BvhDocument parse() {
    parse_hierarchy();
    parse_motion();
    return std::move(doc_);
  }

 private:
  void parse_hierarchy() {
    Token t = lex_.next();
    if (t.text != "HIERARCHY") {
      if (t.eof()) lex_.fail(t.line, "empty file: expected HIERARCHY");
      lex_.fail(t.line, "expected HIERARCHY, found " + quote_token(t.text));
    }
    t = lex_.next();
    if (t.text != "ROOT") {
      if (t.eof()) lex_.fail(t.line, "unexpected end of file: expected ROOT");
      lex_.fail(t.line, "expected ROOT, found " + quote_token(t.text));
    }
    parse_joint(-1, 1);
  }

  void parse_joint(int parent, int depth) {
    const Token name = lex_.next();
    if (name.eof()) lex_.fail(name.line, "unexpected end of file: expected a joint name");
    if (is_brace(name.text[0])) lex_.fail(name.line, "expected a joint name, found " + quote_token(name.text));
    if (depth > kBvhMaxDepth)
      lex_.fail(name.line, "joints nested deeper than " + std::to_string(kBvhMaxDepth) + " levels");
    if (static_cast<int>(doc_.joints.size()) >= kBvhMaxJoints)
      lex_.fail(name.line, "more than " + std::to_string(kBvhMaxJoints) + " joints");
    if (!names_.insert(std::string(name.text)).second)
      lex_.fail(name.line, "duplicate joint name " + quote_token(name.text));

    const int index = static_cast<int>(doc_.joints.size());
    doc_.joints.emplace_back();
    doc_.joints[index].name = std::string(name.text);
    doc_.joints[index].parent = parent;
    expect("{", "after joint " + quote_token(name.text));
    parse_joint_body(index, depth);
  }

  void parse_joint_body(int index, int depth) {
    const std::string where = "joint " + quote_token(doc_.joints[index].name);
    bool has_offset = false, has_channels = false;
    for (;;) {
      const Token t = lex_.next();
      if (t.eof()) lex_.fail(t.line, "unexpected end of file inside " + where);
      if (t.text == "}") {
        if (!has_offset) lex_.fail(t.line, where + " has no OFFSET");
        return;
      } else if (t.text == "OFFSET") {
        if (has_offset) lex_.fail(t.line, where + " has more than one OFFSET");
        has_offset = true;
        doc_.joints[index].offset = parse_vector3();
      } else if (t.text == "CHANNELS") {
        if (has_channels) lex_.fail(t.line, where + " has more than one CHANNELS line");
        has_channels = true;
        doc_.joints[index].channels = parse_channels(t);
      } else if (t.text == "JOINT") {
        parse_joint(index, depth + 1);
      } else if (t.text == "End") {
        parse_end_site(index, t);
      } else {
        lex_.fail(t.line, "unknown keyword " + quote_token(t.text) + " in " + where);
      }
    }
  }

  void parse_end_site(int index, const Token& end_token) {
    BvhJoint& joint = doc_.joints[index];
    const std::string where = "the End Site of joint " + quote_token(joint.name);
    expect("Site", "after End");
    if (joint.has_end_site)
      lex_.fail(end_token.line, "joint " + quote_token(joint.name) + " has more than one End Site");
    expect("{", "after End Site");
    expect("OFFSET", "in " + where);
    joint.end_site = parse_vector3();
    joint.has_end_site = true;
    expect("}", "to close " + where);
  }

  std::vector<BvhChannel> parse_channels(const Token& keyword) {
    const long long count = parse_integer(lex_.next(), "CHANNELS count");
    if (count < 0 || count > 6)
      lex_.fail(keyword.line, "CHANNELS count " + std::to_string(count) + " must be between 0 and 6");
    std::vector<BvhChannel> channels;
    for (long long n = 0; n < count; ++n) {
      const Token t = lex_.peek();
      if (t.eof() || is_hierarchy_keyword(t.text))
        lex_.fail(keyword.line,
                  "CHANNELS " + std::to_string(count) + " lists only " + std::to_string(n) + " channel names");
      lex_.next();
      BvhChannel c;
      if (!channel_from_name(t.text, &c)) lex_.fail(t.line, "unknown channel name " + quote_token(t.text));
      for (BvhChannel seen : channels)
        if (seen == c) lex_.fail(t.line, "channel " + quote_token(t.text) + " listed twice");
      channels.push_back(c);
    }
    return channels;
  }

  void parse_motion() {
    Token t = lex_.next();
    if (t.text == "ROOT") lex_.fail(t.line, "more than one ROOT is not supported");
    if (t.eof()) lex_.fail(t.line, "missing MOTION section");
    if (t.text != "MOTION") lex_.fail(t.line, "expected MOTION, found " + quote_token(t.text));
    const int motion_line = t.line;

    expect("Frames:", "after MOTION");
    const Token frames_token = lex_.next();
    const long long frames = parse_integer(frames_token, "frame count");
    expect("Frame", "after the frame count");
    expect("Time:", "after Frame");
    const double frame_time = parse_number(lex_.next(), "frame time");
    if (frame_time <= 0) lex_.fail(lex_.line(), "frame time must be positive");

    const long long channels = doc_.num_channels();
    if (channels == 0) lex_.fail(motion_line, "the hierarchy has no channels");
    check_frame_count(frames, channels, frames_token.line);
    doc_.num_frames = static_cast<int>(frames);
    doc_.frame_time = frame_time;
    read_values(frames * channels, channels);
  }

  // The limits are checked before anything is allocated for the values.
  void check_frame_count(long long frames, long long channels, int line) {
    if (frames < 1) lex_.fail(line, "Frames: " + std::to_string(frames) + " must be at least 1");
    if (frames > kBvhMaxFrames)
      lex_.fail(line, "Frames: " + std::to_string(frames) + " exceeds the limit of " + std::to_string(kBvhMaxFrames));
    const long long total = frames * channels;
    if (total > kBvhMaxValues)
      lex_.fail(line, "Frames: " + std::to_string(frames) + " x " + std::to_string(channels) +
                          " channels exceeds the limit of " + std::to_string(kBvhMaxValues) + " values");
  }

  void read_values(long long total, long long channels) {
    // Reserve no more than the rest of the input can hold (every number takes at
    // least one character and one separator); a short file then fails below
    // with "unexpected end of file" having allocated only what it contains.
    const unsigned long long fits = (lex_.remaining() + 1) / 2;
    doc_.values.reserve(static_cast<size_t>(std::min<unsigned long long>(total, fits)));
    for (long long n = 0; n < total; ++n) {
      const Token t = lex_.next();
      if (t.eof())
        lex_.fail(t.line, "unexpected end of file in motion data: expected " + std::to_string(total) + " values (" +
                              std::to_string(doc_.num_frames) + " frames x " + std::to_string(channels) +
                              " channels), found " + std::to_string(n));
      doc_.values.push_back(parse_number(t, "motion value"));
    }
    const Token extra = lex_.next();
    if (!extra.eof())
      lex_.fail(extra.line, "more motion data than Frames: " + std::to_string(doc_.num_frames) + " announces (" +
                                std::to_string(channels) + " values per frame); extra value " +
                                quote_token(extra.text));
  }

  Eigen::Vector3d parse_vector3() {
    Eigen::Vector3d v;
    for (int k = 0; k < 3; ++k) v[k] = parse_number(lex_.next(), "OFFSET value");
    return v;
  }

  double parse_number(const Token& t, const std::string& what) {
    if (t.eof()) lex_.fail(t.line, "unexpected end of file: expected " + what);
    std::string_view s = t.text;
    if (s.size() > 1 && s[0] == '+' && s[1] != '-') s.remove_prefix(1);
    double value = 0;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (ptr != s.data() + s.size() || (ec != std::errc() && ec != std::errc::result_out_of_range))
      lex_.fail(t.line, "bad number " + quote_token(t.text) + " for " + what);
    if (ec == std::errc::result_out_of_range) {
      if (!has_negative_exponent(s)) lex_.fail(t.line, "number " + quote_token(t.text) + " is out of range");
      value = 0;  // underflow
    }
    if (!std::isfinite(value)) lex_.fail(t.line, "non-finite value " + quote_token(t.text) + " for " + what);
    return value;
  }

  long long parse_integer(const Token& t, const std::string& what) {
    if (t.eof()) lex_.fail(t.line, "unexpected end of file: expected " + what);
    long long value = 0;
    const auto [ptr, ec] = std::from_chars(t.text.data(), t.text.data() + t.text.size(), value);
    if (ec == std::errc::result_out_of_range) lex_.fail(t.line, what + " " + quote_token(t.text) + " is too large");
    if (ec != std::errc() || ptr != t.text.data() + t.text.size())
      lex_.fail(t.line, "bad " + what + " " + quote_token(t.text) + " (expected an integer)");
    return value;
  }

  void expect(std::string_view word, const std::string& context) {
    const Token t = lex_.next();
    if (t.text == word) return;
    if (t.eof()) lex_.fail(t.line, "unexpected end of file: expected '" + std::string(word) + "' " + context);
    lex_.fail(t.line, "expected '" + std::string(word) + "' " + context + ", found " + quote_token(t.text));
  }

  Lexer lex_;
  BvhDocument doc_;
  std::unordered_set<std::string> names_;
};

// ---------------------------------------------------------------------------
// Writer

void append_number(std::string& out, double v) {
  char buf[64];
  const auto result = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 9);
  out.append(buf, result.ptr);
}

void append_vector3(std::string& out, const Eigen::Vector3d& v) {
  for (int k = 0; k < 3; ++k) {
    out += ' ';
    append_number(out, v[k]);
  }
}

class Writer {
 public:
  explicit Writer(const BvhDocument& doc) : doc_(doc), children_(doc.joints.size()) {
    for (size_t j = 1; j < doc.joints.size(); ++j) children_[doc.joints[j].parent].push_back(static_cast<int>(j));
  }

  std::string format() {
    out_ = "HIERARCHY\n";
    write_joint(0, 0);
    write_motion();
    return std::move(out_);
  }

 private:
  void write_joint(int j, int depth) {
    const BvhJoint& joint = doc_.joints[j];
    const std::string indent(depth, '\t'), inner(depth + 1, '\t');
    out_ += indent + (j == 0 ? "ROOT " : "JOINT ") + joint.name + "\n" + indent + "{\n";
    out_ += inner + "OFFSET";
    append_vector3(out_, joint.offset);
    out_ += "\n" + inner + "CHANNELS " + std::to_string(joint.channels.size());
    for (BvhChannel c : joint.channels) out_ += std::string(" ") + to_string(c);
    out_ += "\n";
    for (int child : children_[j]) write_joint(child, depth + 1);
    if (joint.has_end_site) {
      out_ += inner + "End Site\n" + inner + "{\n" + inner + "\tOFFSET";
      append_vector3(out_, joint.end_site);
      out_ += "\n" + inner + "}\n";
    }
    out_ += indent + "}\n";
  }

  void write_motion() {
    out_ += "MOTION\nFrames: " + std::to_string(doc_.num_frames) + "\nFrame Time: ";
    append_number(out_, doc_.frame_time);
    out_ += "\n";
    const size_t channels = doc_.num_channels();
    for (size_t f = 0; f < static_cast<size_t>(doc_.num_frames); ++f) {
      for (size_t c = 0; c < channels; ++c) {
        if (c > 0) out_ += ' ';
        append_number(out_, doc_.values[f * channels + c]);
      }
      out_ += "\n";
    }
  }

  const BvhDocument& doc_;
  std::vector<std::vector<int>> children_;
  std::string out_;
};

bool is_valid_name(const std::string& name) {
  if (name.empty()) return false;
  for (char c : name)
    if (is_space(c) || is_brace(c)) return false;
  return true;
}

void validate_joint(const BvhDocument& doc, int j, std::unordered_set<std::string>& names) {
  const BvhJoint& joint = doc.joints[j];
  const std::string where = "BVH joint " + std::to_string(j) + " (" + quote_token(joint.name) + ")";
  if (!is_valid_name(joint.name)) throw InputError(where + ": names must be non-empty, without spaces or braces");
  if (!names.insert(joint.name).second) throw InputError(where + ": duplicate joint name");
  if (j == 0 && joint.parent != -1) throw InputError(where + ": joint 0 must be the root (parent -1)");
  if (j > 0 && (joint.parent < 0 || joint.parent >= j))
    throw InputError(where + ": parent " + std::to_string(joint.parent) + " must be an earlier joint");
  if (joint.channels.size() > 6) throw InputError(where + ": more than 6 channels");
  for (size_t a = 0; a < joint.channels.size(); ++a)
    for (size_t b = a + 1; b < joint.channels.size(); ++b)
      if (joint.channels[a] == joint.channels[b]) throw InputError(where + ": a channel is listed twice");
  if (!joint.offset.allFinite() || !joint.end_site.allFinite()) throw InputError(where + ": non-finite offset");
}

// Depth-first order: the parent of joint j is j-1 or one of its ancestors.
// Returns the nesting depth of joint j (root = 1).
int depth_first_depth(const BvhDocument& doc, int j, const std::vector<int>& depths) {
  if (j == 0) return 1;
  const int parent = doc.joints[j].parent;
  for (int a = j - 1; a != parent; a = doc.joints[a].parent)
    if (a < 0) throw InputError("BVH joint " + quote_token(doc.joints[j].name) + " is not in depth-first order");
  return depths[parent] + 1;
}

}  // namespace

// ---------------------------------------------------------------------------
// Public API

const char* to_string(BvhChannel c) {
  switch (c) {
    case BvhChannel::Xposition:
      return "Xposition";
    case BvhChannel::Yposition:
      return "Yposition";
    case BvhChannel::Zposition:
      return "Zposition";
    case BvhChannel::Xrotation:
      return "Xrotation";
    case BvhChannel::Yrotation:
      return "Yrotation";
    case BvhChannel::Zrotation:
      return "Zrotation";
  }
  return "?";
}

int BvhDocument::num_channels() const {
  int n = 0;
  for (const BvhJoint& j : joints) n += static_cast<int>(j.channels.size());
  return n;
}

int BvhDocument::channel_offset(int joint) const {
  int n = 0;
  for (int j = 0; j < joint; ++j) n += static_cast<int>(joints[j].channels.size());
  return n;
}

int BvhDocument::find(const std::string& name) const {
  for (size_t j = 0; j < joints.size(); ++j)
    if (joints[j].name == name) return static_cast<int>(j);
  return -1;
}

void BvhDocument::validate() const {
  if (joints.empty()) throw InputError("BVH document has no joints");
  if (joints.size() > static_cast<size_t>(kBvhMaxJoints))
    throw InputError("BVH document has more than " + std::to_string(kBvhMaxJoints) + " joints");
  std::unordered_set<std::string> names;
  std::vector<int> depths(joints.size(), 1);
  for (int j = 0; j < static_cast<int>(joints.size()); ++j) {
    validate_joint(*this, j, names);
    depths[j] = depth_first_depth(*this, j, depths);
    if (depths[j] > kBvhMaxDepth)
      throw InputError("BVH joints nested deeper than " + std::to_string(kBvhMaxDepth) + " levels");
  }
  if (num_frames < 0) throw InputError("BVH document has a negative frame count");
  if (!(std::isfinite(frame_time) && frame_time >= 0)) throw InputError("BVH frame time must be finite and >= 0");
  const size_t expected = static_cast<size_t>(num_frames) * num_channels();
  if (values.size() != expected)
    throw InputError("BVH document has " + std::to_string(values.size()) + " values, expected " +
                     std::to_string(expected) + " (" + std::to_string(num_frames) + " frames x " +
                     std::to_string(num_channels()) + " channels)");
  for (double v : values)
    if (!std::isfinite(v)) throw InputError("BVH document has a non-finite channel value");
}

BvhDocument parse_bvh(const std::string& text, const std::string& source) { return Parser(text, source).parse(); }

BvhDocument read_bvh_file(const std::string& path) {
  return parse_bvh(read_file_limited(path, "BVH file", kMaxBvhFileBytes), path);
}

std::string format_bvh(const BvhDocument& doc) {
  doc.validate();
  if (doc.num_frames < 1) throw InputError("cannot write a BVH document without frames");
  if (!(doc.frame_time > 0)) throw InputError("cannot write a BVH document with a frame time <= 0");
  return Writer(doc).format();
}

void write_bvh_file(const std::string& path, const BvhDocument& doc) {
  const std::string text = format_bvh(doc);
  write_file_atomically(path, text.data(), text.size());
}

}  // namespace mf
