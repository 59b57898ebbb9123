#include "tasks/constraints/constraint_spec.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>

#include "prior/motion/errors.h"
#include "prior/util/strict_json.h"

namespace mf {
namespace {

using nlohmann::json;

// Reads fields of one JSON object and rejects the ones nobody read (typos).
class Fields {
 public:
  Fields(const json& object, std::string where) : o_(object), where_(std::move(where)) {
    if (!o_.is_object()) fail("must be a JSON object");
  }
  [[noreturn]] void fail(const std::string& what) const { throw InputError(where_ + " " + what); }
  bool has(const char* name) {
    seen_.insert(name);
    return o_.contains(name);
  }
  const json& get(const char* name) {
    if (!has(name)) fail("needs \"" + std::string(name) + "\"");
    return o_.at(name);
  }
  int frame(const char* name) {
    const json& v = get(name);
    if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<long long>() > std::numeric_limits<int>::max())
      fail("\"" + std::string(name) + "\" must be a non-negative integer frame number");
    return v.get<int>();
  }
  std::string name(const char* field) {
    const json& v = get(field);
    if (!v.is_string() || v.get<std::string>().empty()) fail("\"" + std::string(field) + "\" must be a joint name");
    return v.get<std::string>();
  }
  double number(const char* field) {
    const json& v = get(field);
    if (!v.is_number() || !std::isfinite(v.get<double>())) fail("\"" + std::string(field) + "\" must be a finite number");
    return v.get<double>();
  }
  void done() const {
    for (auto it = o_.begin(); it != o_.end(); ++it) {
      if (!seen_.count(it.key())) fail("has an unknown field \"" + it.key() + "\"");
    }
  }

 private:
  const json& o_;
  std::string where_;
  std::set<std::string> seen_;
};

const json& array_field(Fields& top, const char* name) {
  static const json empty = json::array();
  if (!top.has(name)) return empty;
  const json& a = top.get(name);
  if (!a.is_array()) top.fail("field \"" + std::string(name) + "\" must be an array");
  return a;
}

KeySpec parse_key(const json& item, const std::string& where) {
  Fields f(item, where);
  KeySpec k;
  k.frame = f.frame("frame");
  const bool joints = f.has("joints"), root = f.has("root");
  k.whole = !joints && !root;
  if (joints) {
    const json& list = f.get("joints");
    if (!list.is_array()) f.fail("\"joints\" must be an array of joint names");
    for (const json& n : list) {
      if (!n.is_string() || n.get<std::string>().empty()) f.fail("\"joints\" must be an array of joint names");
      k.joints.push_back(n.get<std::string>());
    }
  }
  if (root) {
    const json& r = f.get("root");
    const std::string v = r.is_string() ? r.get<std::string>() : "";
    if (v != "none" && v != "position" && v != "rotation" && v != "both")
      f.fail("\"root\" must be \"none\", \"position\", \"rotation\" or \"both\"");
    k.root_position = v == "position" || v == "both";
    k.root_rotation = v == "rotation" || v == "both";
  }
  if (!k.whole && k.joints.empty() && !k.root_position && !k.root_rotation) f.fail("constrains nothing");
  f.done();
  return k;
}

TargetSpec parse_target(const json& item, const std::string& where) {
  Fields f(item, where);
  TargetSpec t;
  t.frame = f.frame("frame");
  t.joint = f.name("joint");
  const json& p = f.get("position");
  if (!p.is_array() || p.size() != 3) f.fail("\"position\" must be [x, y, z]");
  for (int i = 0; i < 3; ++i) {
    if (!p[i].is_number() || !std::isfinite(p[i].get<double>())) f.fail("\"position\" must hold finite numbers");
    t.position[i] = p[i].get<double>();
  }
  if (f.has("weight")) {
    t.weight = f.number("weight");
    if (t.weight < 0) f.fail("\"weight\" must be non-negative");
  }
  f.done();
  return t;
}

ContactSpec parse_contact(const json& item, const std::string& where) {
  Fields f(item, where);
  ContactSpec c;
  c.joint = f.name("joint");
  c.first = f.frame("first");
  c.last = f.frame("last");
  f.done();
  return c;
}

TrajectoryPoint parse_trajectory_row(const json& item, const std::string& where) {
  Fields f(item, where);
  TrajectoryPoint p;
  p.frame = f.frame("frame");
  p.x = f.number("x");
  p.z = f.number("z");
  p.forward_x = f.number("forward_x");
  p.forward_z = f.number("forward_z");
  if (std::hypot(p.forward_x, p.forward_z) < 1e-6) f.fail("has a facing direction (forward_x, forward_z) of zero length");
  f.done();
  return p;
}

int joint_index(const Skeleton& skel, const std::string& name, const std::string& where) {
  const int j = skel.find(name);
  if (j >= 0) return j;
  std::string names;
  for (const std::string& n : skel.names) names += (names.empty() ? "" : ", ") + n;
  throw InputError(where + ": unknown joint '" + name + "' (the motion's joints: " + names + ")");
}

// Two keys at one frame: what either constrains (a whole pose covers all).
void merge_key(const PoseKey& k, PoseKey* into) {
  const bool whole_k = k.rotations && k.joints.empty(), whole_into = into->rotations && into->joints.empty();
  if (whole_k || whole_into) {
    into->joints.clear();
    into->rotations = true;
  } else if (k.rotations) {
    std::vector<int> joints = into->joints;
    joints.insert(joints.end(), k.joints.begin(), k.joints.end());
    std::sort(joints.begin(), joints.end());
    joints.erase(std::unique(joints.begin(), joints.end()), joints.end());
    into->joints = joints;
    into->rotations = true;
  }
  into->root_position = into->root_position || k.root_position;
}

}  // namespace

ConstraintSpec ConstraintSpec::parse_json(const std::string& text, const std::string& source) {
  const json doc = parse_json_strict(text, source);
  Fields top(doc, source + ":");
  ConstraintSpec spec;
  const json& keys = array_field(top, "keys");
  for (size_t i = 0; i < keys.size(); ++i)
    spec.keys.push_back(parse_key(keys[i], source + ": keys[" + std::to_string(i) + "]"));
  const json& targets = array_field(top, "targets");
  for (size_t i = 0; i < targets.size(); ++i)
    spec.targets.push_back(parse_target(targets[i], source + ": targets[" + std::to_string(i) + "]"));
  const json& contacts = array_field(top, "contacts");
  for (size_t i = 0; i < contacts.size(); ++i)
    spec.contacts.push_back(parse_contact(contacts[i], source + ": contacts[" + std::to_string(i) + "]"));
  const json& trajectory = array_field(top, "trajectory");
  for (size_t i = 0; i < trajectory.size(); ++i)
    spec.trajectory.push_back(parse_trajectory_row(trajectory[i], source + ": trajectory[" + std::to_string(i) + "]"));
  top.done();
  return spec;
}

void ConstraintSpec::append(const ConstraintSpec& other) {
  keys.insert(keys.end(), other.keys.begin(), other.keys.end());
  targets.insert(targets.end(), other.targets.begin(), other.targets.end());
  contacts.insert(contacts.end(), other.contacts.begin(), other.contacts.end());
  trajectory.insert(trajectory.end(), other.trajectory.begin(), other.trajectory.end());
}

void ConstraintSpec::add_whole_pose_keys(const std::vector<int>& frames) {
  for (int f : frames) {
    KeySpec k;
    k.frame = f;
    keys.push_back(k);
  }
}

MotionConstraints ConstraintSpec::resolve(const Skeleton& skel, double length_scale) const {
  MotionConstraints c;
  for (const KeySpec& k : keys) {
    const std::string where = "key at frame " + std::to_string(k.frame);
    PoseKey key;
    key.frame = k.frame;
    if (!k.whole) {
      std::vector<int> joints;
      for (const std::string& n : k.joints) joints.push_back(joint_index(skel, n, where));
      if (k.root_rotation) joints.push_back(0);
      std::sort(joints.begin(), joints.end());
      joints.erase(std::unique(joints.begin(), joints.end()), joints.end());
      key.root_position = k.root_position;
      key.rotations = !joints.empty();  // false: the root position alone
      key.joints = joints;
    }
    c.keys.push_back(key);
  }
  std::stable_sort(c.keys.begin(), c.keys.end(), [](const PoseKey& a, const PoseKey& b) { return a.frame < b.frame; });
  std::vector<PoseKey> merged;
  for (const PoseKey& k : c.keys) {
    if (merged.empty() || merged.back().frame != k.frame) {
      merged.push_back(k);
    } else {
      merge_key(k, &merged.back());
    }
  }
  c.keys = std::move(merged);
  for (const TargetSpec& t : targets) {
    EffectorTarget e;
    e.frame = t.frame;
    e.joint = joint_index(skel, t.joint, "target at frame " + std::to_string(t.frame));
    e.position = t.position * length_scale;
    e.weight = t.weight;
    c.effectors.push_back(e);
  }
  for (const ContactSpec& p : contacts) {
    ContactPin pin;
    pin.joint = joint_index(skel, p.joint, "contact " + std::to_string(p.first) + ".." + std::to_string(p.last));
    pin.first = p.first;
    pin.last = p.last;
    c.contacts.push_back(pin);
  }
  for (const TrajectoryPoint& p : trajectory) {
    TrajectoryPoint q = p;
    q.x *= length_scale;
    q.z *= length_scale;
    c.trajectory.push_back(q);
  }
  std::stable_sort(c.trajectory.begin(), c.trajectory.end(),
                   [](const TrajectoryPoint& a, const TrajectoryPoint& b) { return a.frame < b.frame; });
  return c;
}

std::string ConstraintSpec::to_json() const {
  json doc = json::object();
  json k = json::array(), t = json::array(), c = json::array();
  for (const KeySpec& key : keys) {
    json o = {{"frame", key.frame}};
    if (!key.whole) {
      o["joints"] = key.joints;
      o["root"] = key.root_position ? (key.root_rotation ? "both" : "position") : (key.root_rotation ? "rotation" : "none");
    }
    k.push_back(o);
  }
  for (const TargetSpec& e : targets)
    t.push_back({{"frame", e.frame}, {"joint", e.joint}, {"position", {e.position.x(), e.position.y(), e.position.z()}},
                 {"weight", e.weight}});
  for (const ContactSpec& p : contacts) c.push_back({{"joint", p.joint}, {"first", p.first}, {"last", p.last}});
  doc["keys"] = k;
  doc["targets"] = t;
  doc["contacts"] = c;
  if (!trajectory.empty()) {
    json r = json::array();
    for (const TrajectoryPoint& p : trajectory)
      r.push_back({{"frame", p.frame}, {"x", p.x}, {"z", p.z}, {"forward_x", p.forward_x}, {"forward_z", p.forward_z}});
    doc["trajectory"] = r;
  }
  return doc.dump(2);
}

}  // namespace mf
