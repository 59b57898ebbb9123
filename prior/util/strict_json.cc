#include "prior/util/strict_json.h"

#include <set>
#include <vector>

#include "prior/motion/errors.h"

namespace mf {

namespace {

// Where the parser is: one frame per open object or array.
class Path {
 public:
  void open(bool array) { frames_.push_back(Frame{array, 0, "", {}}); }
  void close() {
    frames_.pop_back();
    next_item();
  }
  void next_item() {
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
  }
  // Records `key` in the open object; false when it was there already.
  bool add_key(const std::string& key) {
    if (frames_.empty()) return true;
    frames_.back().key = key;
    return frames_.back().keys.insert(key).second;
  }
  // The path of the open object.
  std::string where() const {
    std::string path;
    for (size_t i = 0; i + 1 < frames_.size(); ++i) {
      const Frame& f = frames_[i];
      path += f.array ? "[" + std::to_string(f.index) + "]" : (path.empty() ? "" : ".") + f.key;
    }
    return path.empty() ? "the top-level object" : path;
  }

 private:
  struct Frame {
    bool array;
    size_t index;
    std::string key;
    std::set<std::string> keys;
  };
  std::vector<Frame> frames_;
};

}  // namespace

nlohmann::json parse_json_strict(const std::string& text, const std::string& source) {
  using json = nlohmann::json;
  Path path;
  std::string duplicate;
  const auto callback = [&](int, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start: path.open(false); break;
      case json::parse_event_t::array_start: path.open(true); break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end: path.close(); break;
      case json::parse_event_t::value: path.next_item(); break;
      case json::parse_event_t::key: {
        const std::string key = parsed.get<std::string>();
        if (!path.add_key(key) && duplicate.empty())
          duplicate = "duplicate key \"" + key + "\" in " + path.where();
        break;
      }
    }
    return true;
  };
  json doc;
  try {
    doc = json::parse(text, callback);
  } catch (const json::exception& e) {
    throw InputError(source + ": not valid JSON (" + std::string(e.what()) + ")");
  }
  if (!duplicate.empty()) throw InputError(source + ": " + duplicate);
  return doc;
}

}  // namespace mf
