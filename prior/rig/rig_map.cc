#include "prior/rig/rig_map.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "prior/motion/errors.h"
#include "prior/util/binary_io.h"

namespace mf {
namespace {

enum class Kind { None, Helper, Finger, Hips, Spine, Chest, Neck, Head, Shoulder, Clavicle, UpperArm, Fore, Hand,
                  Thigh, Shin, Foot, Toe };

// Lower-case words of a joint name: namespace prefixes dropped, split at
// separators, camel-case humps and letter/digit boundaries; digits dropped.
std::vector<std::string> name_words(const std::string& raw) {
  std::string name = raw;
  const size_t cut = name.find_last_of(":|");
  if (cut != std::string::npos) name = name.substr(cut + 1);
  std::vector<std::string> words;
  std::string cur;
  auto flush = [&] {
    if (!cur.empty()) words.push_back(cur);
    cur.clear();
  };
  for (size_t i = 0; i < name.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(name[i]);
    if (!std::isalpha(c)) {
      flush();
      continue;
    }
    const bool upper = std::isupper(c);
    const bool prev_lower = i > 0 && std::islower(static_cast<unsigned char>(name[i - 1]));
    const bool next_lower = i + 1 < name.size() && std::islower(static_cast<unsigned char>(name[i + 1]));
    const bool prev_upper = i > 0 && std::isupper(static_cast<unsigned char>(name[i - 1]));
    if (upper && (prev_lower || (prev_upper && next_lower))) flush();
    cur += static_cast<char>(std::tolower(c));
  }
  flush();
  // Rig-tool prefixes that carry no meaning.
  static const std::set<std::string> noise = {"mixamorig", "bip", "def", "org", "mch", "jnt", "bn", "b", "j", "ctrl",
                                              "sk", "m", "f", "avg"};
  std::vector<std::string> kept;
  for (const std::string& w : words)
    if (!noise.count(w)) kept.push_back(w);
  return kept;
}

bool is_side_word(const std::string& w, int* side) {
  if (w == "l" || w == "left" || w == "lft") return *side = 0, true;
  if (w == "r" || w == "right" || w == "rgt") return *side = 1, true;
  return false;
}

// A word that names a body part of one side (as in CMU's ASF names after
// their one-letter side: "femur", "humerus", "hipjoint").
bool is_sided_part(const std::string& w) {
  static const std::set<std::string> parts = {
      "hipjoint", "femur",   "tibia",  "foot",    "toes",   "toe",   "clavicle", "humerus", "radius",
      "ulna",     "wrist",   "hand",   "fingers", "thumb",  "thigh", "shin",     "forearm", "upperarm",
      "shoulder", "collar",  "ankle",  "knee",    "elbow",  "upleg", "shldr",    "uparm",   "loarm"};
  return parts.count(w) > 0;
}

// Side and the words without the side.
int split_side(const std::string& name, std::vector<std::string>* rest) {
  int side = -1;
  for (const std::string& w : name_words(name)) {
    int s = -1;
    if (is_side_word(w, &s)) {
      side = s;
    } else if (w.rfind("left", 0) == 0 && w.size() > 4) {
      side = 0;
      rest->push_back(w.substr(4));
    } else if (w.rfind("right", 0) == 0 && w.size() > 5) {
      side = 1;
      rest->push_back(w.substr(5));
    } else if ((w[0] == 'l' || w[0] == 'r') && is_sided_part(w.substr(1))) {
      // CMU's ASF names: "lfemur", "rhumerus", "lhipjoint".
      side = w[0] == 'l' ? 0 : 1;
      rest->push_back(w.substr(1));
    } else {
      rest->push_back(w);
    }
  }
  return side;
}

bool has(const std::vector<std::string>& words, const char* w) {
  return std::find(words.begin(), words.end(), w) != words.end();
}

Kind classify(const std::string& name, int* side) {
  std::vector<std::string> w;
  *side = split_side(name, &w);
  std::string core;
  for (const std::string& s : w) core += s;
  if (core.find("hipjoint") != std::string::npos) return Kind::Helper;  // CMU's LHipJoint: hips to thigh
  w.erase(std::remove(w.begin(), w.end(), "joint"), w.end());
  core.clear();
  for (const std::string& s : w) core += s;
  for (const char* h : {"twist", "roll", "helper", "ik", "pole", "nub", "end", "dummy", "share", "bend", "corrective",
                        "tip", "top", "prop", "weapon", "breast"})
    if (has(w, h) || core == h) return Kind::Helper;
  if (core.find("twist") != std::string::npos) return Kind::Helper;
  for (const char* f : {"thumb", "index", "middle", "ring", "pinky", "little", "finger", "fingers", "carpal", "palm"})
    if (core.find(f) != std::string::npos) return Kind::Finger;
  const bool sided = *side >= 0;
  if (!sided) {
    if (core == "hips" || core == "hip" || core == "pelvis") return Kind::Hips;
    if (core == "neck") return Kind::Neck;
    if (core == "head") return Kind::Head;
    if (core == "chest" || core == "upperchest" || core == "thorax" || core == "ribcage") return Kind::Chest;
    if (core == "spine" || core == "lowerback" || core == "back" || core == "torso" || core == "abdomen" ||
        core == "abs" || core == "waist" || core == "belly" || core == "stomach" || core == "upperback" ||
        core == "lowerspine" || core == "upperspine" || core == "middlespine")
      return Kind::Spine;
    return Kind::None;
  }
  if (core == "clavicle" || core == "collar" || core == "collarbone" || core == "clav") return Kind::Clavicle;
  if (core == "shoulder") return Kind::Shoulder;
  if (core == "upperarm" || core == "arm" || core == "uparm" || core == "humerus" || core == "shldr")
    return Kind::UpperArm;
  if (core == "forearm" || core == "lowerarm" || core == "loarm" || core == "elbow" || core == "radius" ||
      core == "ulna")
    return Kind::Fore;
  if (core == "hand" || core == "wrist") return Kind::Hand;
  if (core == "upleg" || core == "upperleg" || core == "thigh" || core == "femur" || core == "hip" ||
      core == "uleg" || core == "legupper")
    return Kind::Thigh;
  if (core == "leg" || core == "lowerleg" || core == "shin" || core == "calf" || core == "knee" ||
      core == "loleg" || core == "tibia" || core == "leglower")
    return Kind::Shin;
  if (core == "foot" || core == "ankle") return Kind::Foot;
  if (core == "toe" || core == "toes" || core == "toebase" || core == "ball" || core == "football") return Kind::Toe;
  return Kind::None;
}

struct Tree {
  const Skeleton& s;
  std::vector<std::vector<int>> kids;
  std::vector<int> size;  // joints in the subtree
  explicit Tree(const Skeleton& sk) : s(sk), kids(sk.children()), size(sk.num_joints(), 1) {
    for (int j = sk.num_joints() - 1; j > 0; --j) size[sk.parents[j]] += size[j];
  }
  bool is_ancestor(int a, int j) const {  // a is j or above it
    for (; j >= 0; j = s.parents[j])
      if (j == a) return true;
    return false;
  }
  int lca(int a, int b) const {
    for (int x = a; x >= 0; x = s.parents[x])
      if (is_ancestor(x, b)) return x;
    return -1;
  }
  // Joints strictly between ancestor a and descendant d, a's side first.
  std::vector<int> between(int a, int d) const {
    std::vector<int> path;
    for (int j = s.parents[d]; j >= 0 && j != a; j = s.parents[j]) path.push_back(j);
    std::reverse(path.begin(), path.end());
    return path;
  }
  // From j down along the child with the largest subtree, j included.
  std::vector<int> main_chain(int j) const {
    std::vector<int> chain{j};
    while (!kids[j].empty()) {
      j = *std::max_element(kids[j].begin(), kids[j].end(), [&](int a, int b) { return size[a] < size[b]; });
      chain.push_back(j);
    }
    return chain;
  }
};

// Fills a limb's missing joints from its chain's significant joints (named
// helpers, fingers and zero-length joints skipped), in order.
std::vector<int> significant(const Tree& t, const std::vector<int>& chain, const std::vector<Kind>& kinds) {
  std::vector<int> out;
  for (int j : chain) {
    if (kinds[j] == Kind::Helper || kinds[j] == Kind::Finger) continue;
    if (j != chain.front() && t.s.offsets[j].norm() < 1e-9) continue;  // coincides with its parent
    out.push_back(j);
  }
  return out;
}

const char* side_name(int s) { return s == 0 ? "left" : "right"; }

}  // namespace

int name_side(const std::string& name) {
  std::vector<std::string> rest;
  return split_side(name, &rest);
}

std::vector<int> mirror_counterparts(const Skeleton& skeleton) {
  const int J = skeleton.num_joints();
  std::vector<int> side(J);
  std::vector<std::vector<std::string>> words(J);
  for (int j = 0; j < J; ++j) side[j] = split_side(skeleton.names[j], &words[j]);
  std::vector<int> counterpart(J, -1);
  for (int j = 0; j < J; ++j) {
    if (side[j] < 0) {
      counterpart[j] = j;
      continue;
    }
    for (int k = 0; k < J && counterpart[j] < 0; ++k)
      if (side[k] == 1 - side[j] && words[k] == words[j]) counterpart[j] = k;
    if (counterpart[j] < 0)
      throw InputError("joint '" + skeleton.names[j] + "' has no " + side_name(1 - side[j]) +
                       " counterpart: the rig cannot be mirrored");
  }
  for (int j = 1; j < J; ++j) {
    const int p = skeleton.parents[j];
    if (skeleton.parents[counterpart[j]] != counterpart[p])
      throw InputError("joints '" + skeleton.names[j] + "' and '" + skeleton.names[counterpart[j]] +
                       "' are counterparts, but their parents are not: the rig cannot be mirrored");
  }
  return counterpart;
}

namespace {

// The steps of find_rig_parts over one skeleton, each filling what it can.
struct PartFinder {
  const Skeleton& s;
  Tree t;
  std::vector<Kind> kinds;
  std::vector<int> sides;
  RigParts p;

  explicit PartFinder(const Skeleton& sk) : s(sk), t(sk), kinds(sk.num_joints()), sides(sk.num_joints()) {
    for (int j = 0; j < sk.num_joints(); ++j) kinds[j] = classify(sk.names[j], &sides[j]);
  }

  // Topmost joint of a kind and side under `below` (anywhere when below < 0).
  int first_of(Kind k, int side, int below) const {
    for (int j = 0; j < s.num_joints(); ++j)
      if (kinds[j] == k && sides[j] == side && (below < 0 || (j != below && t.is_ancestor(below, j)))) return j;
    return -1;
  }

  // The largest child of `j` on `side` (-1: unsided).
  int largest_child(int j, int side) const {
    int best = -1;
    for (int c : t.kids[j])
      if (sides[c] == side && (best < 0 || t.size[c] > t.size[best])) best = c;
    return best;
  }

  void legs_by_name() {
    for (int side = 0; side < 2; ++side) {
      LegParts& l = p.legs[side];
      l.thigh = first_of(Kind::Thigh, side, -1);
      l.shin = first_of(Kind::Shin, side, l.thigh);
      l.foot = first_of(Kind::Foot, side, l.shin >= 0 ? l.shin : l.thigh);
      if (l.foot >= 0) {
        l.toe = first_of(Kind::Toe, side, l.foot);
        if (l.toe < 0) l.toe = first_of(Kind::Foot, side, l.foot);  // SMPL: ankle, then foot = toes
      }
    }
  }

  // Where both legs meet, else a joint named like the hips.
  void hips() {
    if (p.legs[0].thigh >= 0 && p.legs[1].thigh >= 0) p.hips = t.lca(p.legs[0].thigh, p.legs[1].thigh);
    for (int j = 0; j < s.num_joints() && p.hips < 0; ++j)
      if (kinds[j] == Kind::Hips) p.hips = j;
  }

  // Where names left gaps: the significant joints of the chain below the
  // hips' child on that side.
  void legs_by_shape() {
    for (int side = 0; side < 2; ++side) {
      LegParts& l = p.legs[side];
      if (l.thigh >= 0 && l.shin >= 0 && l.foot >= 0) continue;
      int root = -1;
      for (int c : t.kids[p.hips])
        if (sides[c] == side || (l.thigh >= 0 && t.is_ancestor(c, l.thigh))) root = c;
      if (root < 0) continue;
      const std::vector<int> sig = significant(t, t.main_chain(root), kinds);
      if (sig.size() < 3) continue;
      l.thigh = sig[0], l.shin = sig[1], l.foot = sig[2], l.toe = sig.size() > 3 ? sig[3] : -1;
    }
  }

  // "shoulder" is the clavicle when an upper arm is named too, else the upper
  // arm (SMPL: L_Collar, L_Shoulder, L_Elbow, L_Wrist).
  void arms_by_name() {
    for (int side = 0; side < 2; ++side) {
      ArmParts& a = p.arms[side];
      const int clav = first_of(Kind::Clavicle, side, p.hips), shoulder = first_of(Kind::Shoulder, side, p.hips);
      a.upper = first_of(Kind::UpperArm, side, p.hips);
      a.shoulder = a.upper >= 0 ? (clav >= 0 ? clav : shoulder) : clav;
      if (a.upper < 0) a.upper = shoulder;
      if (a.shoulder >= 0 && a.upper >= 0 && !t.is_ancestor(a.shoulder, a.upper)) a.shoulder = -1;
      a.fore = first_of(Kind::Fore, side, a.upper);
      a.hand = first_of(Kind::Hand, side, a.fore >= 0 ? a.fore : a.upper);
    }
  }

  // Where both arms meet; by shape, the first joint down the spine side of
  // the hips with two side branches.
  void chest() {
    const int left_top = p.arms[0].shoulder >= 0 ? p.arms[0].shoulder : p.arms[0].upper;
    const int right_top = p.arms[1].shoulder >= 0 ? p.arms[1].shoulder : p.arms[1].upper;
    if (left_top >= 0 && right_top >= 0) p.chest = t.lca(left_top, right_top);
    if (p.chest >= 0 && p.chest != p.hips && t.is_ancestor(p.hips, p.chest)) return;
    p.chest = -1;
    for (int j = largest_child(p.hips, -1); j >= 0 && p.chest < 0; j = largest_child(j, -1)) {
      int sided = 0;
      for (int c : t.kids[j])
        if (sides[c] >= 0 && t.size[c] >= 3) ++sided;
      if (sided >= 2) p.chest = j;
    }
  }

  // Where names left gaps: the chest's side chains up to where fingers branch.
  void arms_by_shape() {
    for (int side = 0; side < 2; ++side) {
      ArmParts& a = p.arms[side];
      if (a.upper >= 0 && a.fore >= 0 && a.hand >= 0) continue;
      // Named upper arm and forearm, the forearm a leaf: a rig without hands.
      if (a.upper >= 0 && a.fore >= 0 && a.hand < 0 && t.kids[a.fore].empty()) {
        a.hand_is_end = true;
        continue;
      }
      const int root = largest_child(p.chest, side);
      if (root < 0) continue;
      std::vector<int> chain;
      for (int j : t.main_chain(root)) {
        chain.push_back(j);
        if (t.kids[j].size() >= 2) break;
      }
      const std::vector<int> sig = significant(t, chain, kinds);
      if (sig.size() >= 4) a = {sig[sig.size() - 4], sig[sig.size() - 3], sig[sig.size() - 2], sig.back()};
      else if (sig.size() == 3) a = {-1, sig[0], sig[1], sig[2]};
    }
  }

  // On the chest's unsided branch: a joint named head, else the branch's end.
  void head_and_neck() {
    for (int j = 0; j < s.num_joints() && p.head < 0; ++j)
      if (kinds[j] == Kind::Head && t.is_ancestor(p.chest, j)) p.head = j;
    const int top = largest_child(p.chest, -1);
    if (p.head < 0 && top >= 0) {
      const std::vector<int> sig = significant(t, t.main_chain(top), kinds);
      if (!sig.empty()) p.head = sig.back();
    }
    if (p.head < 0) return;
    for (int j : t.between(p.chest, p.head))
      if (kinds[j] != Kind::Helper && p.neck < 0) p.neck = j;
  }
};

}  // namespace

RigParts find_rig_parts(const Skeleton& s) {
  if (s.num_joints() == 0) return {};
  PartFinder f(s);
  f.legs_by_name();
  f.hips();
  if (f.p.hips < 0) return f.p;
  f.legs_by_shape();
  f.arms_by_name();
  f.chest();
  if (f.p.chest < 0) return f.p;
  f.p.spine = f.t.between(f.p.hips, f.p.chest);
  f.arms_by_shape();
  f.head_and_neck();
  return f.p;
}

std::vector<std::pair<std::string, int>> RigParts::list() const {
  std::vector<std::pair<std::string, int>> out;
  out.emplace_back("hips", hips);
  for (size_t i = 0; i < spine.size(); ++i) out.emplace_back("spine " + std::to_string(i + 1), spine[i]);
  out.emplace_back("chest", chest);
  out.emplace_back("neck", neck);
  out.emplace_back("head", head);
  for (int s = 0; s < 2; ++s) {
    const std::string side = side_name(s);
    out.emplace_back(side + " shoulder", arms[s].shoulder);
    out.emplace_back(side + " upper arm", arms[s].upper);
    out.emplace_back(side + " forearm", arms[s].fore);
    out.emplace_back(side + " hand", arms[s].hand);
  }
  for (int s = 0; s < 2; ++s) {
    const std::string side = side_name(s);
    out.emplace_back(side + " thigh", legs[s].thigh);
    out.emplace_back(side + " shin", legs[s].shin);
    out.emplace_back(side + " foot", legs[s].foot);
    out.emplace_back(side + " toe", legs[s].toe);
  }
  out.erase(std::remove_if(out.begin(), out.end(), [](const auto& e) { return e.second < 0; }), out.end());
  return out;
}

std::vector<std::string> RigParts::missing() const {
  std::vector<std::string> m;
  if (hips < 0) m.push_back("hips");
  if (chest < 0) m.push_back("chest (where the arms branch off the spine)");
  if (head < 0) m.push_back("head");
  for (int s = 0; s < 2; ++s) {
    const std::string side = side_name(s);
    if (arms[s].upper < 0) m.push_back(side + " upper arm");
    if (arms[s].fore < 0) m.push_back(side + " forearm");
    if (arms[s].hand < 0 && !arms[s].hand_is_end) m.push_back(side + " hand");
    if (legs[s].thigh < 0) m.push_back(side + " thigh");
    if (legs[s].shin < 0) m.push_back(side + " shin");
    if (legs[s].foot < 0) m.push_back(side + " foot");
  }
  return m;
}

std::string RigParts::part_of(int joint) const {
  for (const auto& [name, j] : list())
    if (j == joint) return name;
  return "";
}

namespace {

// The user's parts as `user_of_model` assigns them through the model's parts.
RigParts induced_parts(const RigParts& model, const std::vector<int>& user_of_model, const RigParts& user) {
  auto u = [&](int m) { return m < 0 ? -1 : user_of_model[m]; };
  RigParts p;
  p.hips = u(model.hips);
  for (int m : model.spine)
    if (u(m) >= 0) p.spine.push_back(u(m));
  p.chest = u(model.chest), p.neck = u(model.neck), p.head = u(model.head);
  for (int s = 0; s < 2; ++s) {
    p.arms[s] = {u(model.arms[s].shoulder), u(model.arms[s].upper), u(model.arms[s].fore), u(model.arms[s].hand)};
    p.arms[s].hand_is_end = p.arms[s].hand < 0 && user.arms[s].hand_is_end && p.arms[s].fore == user.arms[s].fore;
    p.legs[s] = {u(model.legs[s].thigh), u(model.legs[s].shin), u(model.legs[s].foot), u(model.legs[s].toe)};
  }
  return p;
}

std::string describe(const RigParts& parts, const Skeleton& s) {
  std::string out;
  for (const auto& [name, j] : parts.list()) out += (out.empty() ? "" : ", ") + name + " = '" + s.names[j] + "'";
  return out.empty() ? "nothing" : out;
}

}  // namespace

namespace {

// The automatic map: the user's parts matched to the model's, part by part.
void match_parts(const Skeleton& user, RigMap* out) {
  RigMap& map = *out;
  const int M = static_cast<int>(map.user_of_model.size());
  const RigParts up = find_rig_parts(user);
  auto set = [&](int m, int u) {
    if (m >= 0 && u >= 0) map.user_of_model[m] = u, map.how[m] = "name";
  };
  set(map.model_parts.hips, up.hips);
  if (!map.model_parts.spine.empty() && !up.spine.empty()) set(map.model_parts.spine.front(), up.spine.front());
  if (map.model_parts.spine.size() >= 2 && up.spine.size() >= 2) set(map.model_parts.spine.back(), up.spine.back());
  set(map.model_parts.chest, up.chest);
  set(map.model_parts.neck, up.neck);
  set(map.model_parts.head, up.head);
  for (int s = 0; s < 2; ++s) {
    const ArmParts& ma = map.model_parts.arms[s];
    const ArmParts& ua = up.arms[s];
    set(ma.shoulder, ua.shoulder), set(ma.upper, ua.upper), set(ma.fore, ua.fore), set(ma.hand, ua.hand);
    const LegParts& ml = map.model_parts.legs[s];
    const LegParts& ul = up.legs[s];
    set(ml.thigh, ul.thigh), set(ml.shin, ul.shin), set(ml.foot, ul.foot), set(ml.toe, ul.toe);
  }
  for (int m = 0; m < M; ++m)  // "shape" where the user's joint was not found by its name
    if (map.user_of_model[m] >= 0) {
      int side = -1;
      const Kind k = classify(user.names[map.user_of_model[m]], &side);
      if (k == Kind::None || k == Kind::Helper) map.how[m] = "shape";
    }
}

// A map file's entries replace what was found for the joints they name.
void apply_map_json(const std::string& map_json, const Skeleton& user, const Skeleton& model, RigMap* out) {
  RigMap& map = *out;
  const int M = model.num_joints();
  std::set<std::string> seen_keys;
  std::string duplicate;
  int depth = 0;
  const auto callback = [&](int, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    if (event == nlohmann::json::parse_event_t::object_start) ++depth;
    if (event == nlohmann::json::parse_event_t::object_end) --depth;
    if (event == nlohmann::json::parse_event_t::key && depth == 1 && !seen_keys.insert(parsed.get<std::string>()).second &&
        duplicate.empty())
      duplicate = parsed.get<std::string>();
    return true;
  };
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(map_json, callback);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(std::string("rig map: not valid JSON (") + e.what() + ")");
  }
  if (!j.is_object()) throw InputError("rig map: expected a JSON object {\"user joint\": \"model joint\", ...}");
  if (!duplicate.empty())
    throw InputError("rig map: user joint '" + duplicate + "' is mapped twice (conflicting entries)");
  std::map<int, std::string> given;  // model joint -> user joint named in the file
  for (auto it = j.begin(); it != j.end(); ++it) {
    const int u = user.find(it.key());
    if (u < 0) throw InputError("rig map: the motion has no joint named '" + it.key() + "'");
    for (int m = 0; m < M; ++m)  // the file's entry replaces what was found for this user joint
      if (map.user_of_model[m] == u) map.user_of_model[m] = -1, map.how[m] = "";
    if (it.value().is_null()) continue;
    if (!it.value().is_string())
      throw InputError("rig map: the value for '" + it.key() + "' must be a model joint name or null");
    const std::string target = it.value().get<std::string>();
    const int m = model.find(target);
    if (m < 0) {
      std::string names;
      for (const std::string& n : model.names) names += (names.empty() ? "" : ", ") + n;
      throw InputError("rig map: the model has no joint named '" + target + "' (its joints: " + names + ")");
    }
    if (given.count(m))
      throw InputError("rig map: model joint '" + target + "' is given two user joints ('" + given[m] + "' and '" +
                       it.key() + "')");
    given[m] = it.key();
    map.user_of_model[m] = u, map.how[m] = "map file";
  }
}

// The map must give every required part and nest like the model.
void check_map(const Skeleton& user, const Skeleton& model, RigMap* out) {
  RigMap& map = *out;
  const int M = model.num_joints();
  const RigParts up = find_rig_parts(user);
  // Parts implied by the (possibly edited) map must make a humanoid whose
  // joints nest like the model's.
  map.user_parts = induced_parts(map.model_parts, map.user_of_model, up);
  const std::vector<std::string> missing = map.user_parts.missing();
  if (!missing.empty()) {
    std::string m;
    for (const std::string& s : missing) m += (m.empty() ? "" : ", ") + s;
    throw InputError("cannot map this skeleton (" + std::to_string(user.num_joints()) +
                     " joints) onto the model's humanoid: found " + describe(up, user) + "; missing " + m +
                     ". Name the joints in a rig map (JSON {\"user joint\": \"model joint\"}, docs/RIGS.md)");
  }
  const Tree t(user);
  for (int m = 1; m < M; ++m) {  // every mapped joint's nearest mapped model ancestor must be a user ancestor too
    const int u = map.user_of_model[m];
    if (u < 0) continue;
    int pm = model.parents[m];
    while (pm >= 0 && map.user_of_model[pm] < 0) pm = model.parents[pm];
    if (pm >= 0 && !(map.user_of_model[pm] != u && t.is_ancestor(map.user_of_model[pm], u)))
      throw InputError("rig map: '" + user.names[u] + "' plays model joint '" + model.names[m] + "', but '" +
                       user.names[map.user_of_model[pm]] + "' (playing '" + model.names[pm] +
                       "') is not above it in the motion's hierarchy");
  }
}

}  // namespace

RigMap map_rig(const Skeleton& user, const Skeleton& model, const std::string& map_json) {
  RigMap map;
  map.model_parts = find_rig_parts(model);
  if (!map.model_parts.missing().empty())
    throw InputError("the model's skeleton is not a humanoid the rig map understands (missing: " +
                     map.model_parts.missing().front() + ")");
  map.user_of_model.assign(model.num_joints(), -1);
  map.how.assign(model.num_joints(), "");
  match_parts(user, &map);
  if (!map_json.empty()) apply_map_json(map_json, user, model, &map);
  check_map(user, model, &map);
  return map;
}

std::string RigMap::to_json(const Skeleton& user, const Skeleton& model) const {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (size_t m = 0; m < user_of_model.size(); ++m)
    if (user_of_model[m] >= 0) j[user.names[user_of_model[m]]] = model.names[m];
  return j.dump(2);
}

std::string read_rig_map_file(const std::string& path) {
  return read_file_limited(path, "rig map file", kMaxRigMapFileBytes);
}

}  // namespace mf
