#include "common/symmetry/spec_parser.hpp"

#include "common/core/config_section.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <map>
#include <set>
#include <vector>

#include "common/core/config_error.hpp"
#include "common/symmetry/kind_action.hpp"

namespace masa::sym {
namespace {

std::string join(const std::vector<std::string>& items) {
  std::string s;
  for (const std::string& item : items) s += (s.empty() ? "" : ", ") + item;
  return s;
}

bool isIdentifier(const std::string& s) {
  if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
  for (char c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
  return true;
}

class Parser {
 public:
  explicit Parser(const std::string& source) : src_(source) {}

  ParsedSpec parse(const YAML::Node& root) {
    if (!root.IsMap()) fail("<document>", "expected a mapping with keys name, group, observation, action", root);
    checkKeys(root, "", {"name", "group", "observation", "action", "mujoco"});
    ParsedSpec spec;
    spec.name = identifier(required(root, "", "name"), "name");
    spec.group = parseGroup(required(root, "", "group"));
    spec.observation = parseBlock(required(root, "", "observation"), "observation", spec.group);
    spec.action = parseBlock(required(root, "", "action"), "action", spec.group);
    if (root["mujoco"].IsDefined()) spec.mujoco = parseMujoco(root["mujoco"], spec);
    return spec;
  }

 private:
  // The config reader's error (common/core/config_section.hpp): file, key path, why, line.
  [[noreturn]] void fail(const std::string& key, std::string msg, const YAML::Node& where) const {
    config::failAt(src_, key, where, std::move(msg));
  }

  static std::string child(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }

  // Unknown or repeated keys are errors: a typo must not silently fall back to a default.
  void checkKeys(const YAML::Node& map, const std::string& path, const std::vector<std::string>& allowed) const {
    std::set<std::string> seen;
    for (auto it = map.begin(); it != map.end(); ++it) {
      if (!it->first.IsScalar()) fail(path.empty() ? "<document>" : path, "keys must be plain strings", it->first);
      const std::string key = it->first.Scalar();
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
        fail(child(path, key), "unknown key; valid keys here: " + join(allowed), it->first);
      if (!seen.insert(key).second) fail(child(path, key), "key given twice", it->first);
    }
  }

  YAML::Node required(const YAML::Node& map, const std::string& path, const std::string& key) const {
    const YAML::Node n = map[key];
    if (!n.IsDefined() || n.IsNull()) fail(child(path, key), "missing required key", map);
    return n;
  }

  std::string scalar(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar() || n.Scalar().empty()) fail(key, "expected a non-empty string", n);
    return n.Scalar();
  }

  std::string identifier(const YAML::Node& n, const std::string& key) const {
    const std::string s = scalar(n, key);
    if (!isIdentifier(s))
      fail(key, "'" + s + "' is not a valid name (letters, digits and '_', not starting with a digit)", n);
    return s;
  }

  int integer(const YAML::Node& n, const std::string& key) const {
    if (n.IsScalar()) {
      try {
        return n.as<int>();
      } catch (const YAML::Exception&) {
      }
    }
    fail(key, "expected an integer" + (n.IsScalar() ? ", got '" + n.Scalar() + "'" : std::string()), n);
  }

  std::vector<std::string> nameList(const YAML::Node& n, const std::string& key, int expected) const {
    if (!n.IsSequence()) fail(key, "expected a list of names", n);
    if (static_cast<int>(n.size()) != expected)
      fail(key, "has " + std::to_string(n.size()) + " names but the action layout has " + std::to_string(expected) +
                    " entries here", n);
    std::vector<std::string> names;
    for (std::size_t k = 0; k < n.size(); ++k) names.push_back(scalar(n[k], key + "[" + std::to_string(k) + "]"));
    return names;
  }

  MujocoBinding parseMujoco(const YAML::Node& n, const ParsedSpec& spec) const {
    if (!n.IsMap()) fail("mujoco", "expected a mapping with keys actuators, free_joints", n);
    checkKeys(n, "mujoco", {"actuators", "free_joints"});
    MujocoBinding b;
    b.present = true;
    const YAML::Node act = required(n, "mujoco", "actuators");
    if (!act.IsMap()) fail("mujoco.actuators", "expected a mapping with keys central, limbs", act);
    checkKeys(act, "mujoco.actuators", {"central", "limbs"});
    const int n_agents = spec.group.order;
    if (act["central"].IsDefined())
      b.central_actuators = nameList(act["central"], "mujoco.actuators.central", spec.action.centralDim());
    else if (spec.action.centralDim() != 0)
      fail("mujoco.actuators.central", "missing: the action layout has central entries", act);
    const YAML::Node limbs = required(act, "mujoco.actuators", "limbs");
    if (!limbs.IsSequence() || static_cast<int>(limbs.size()) != n_agents)
      fail("mujoco.actuators.limbs", "expected one list of actuator names per limb (" + std::to_string(n_agents) + ")",
           limbs);
    for (int k = 0; k < n_agents; ++k)
      b.limb_actuators.push_back(
          nameList(limbs[k], "mujoco.actuators.limbs[" + std::to_string(k) + "]", spec.action.limbDim()));
    if (n["free_joints"].IsDefined()) {
      const YAML::Node fj = n["free_joints"];
      if (!fj.IsSequence()) fail("mujoco.free_joints", "expected a list of {name, kind}", fj);
      for (std::size_t k = 0; k < fj.size(); ++k) {
        const std::string at = "mujoco.free_joints[" + std::to_string(k) + "]";
        if (!fj[k].IsMap()) fail(at, "expected {name: ..., kind: robot_base|object}", fj[k]);
        checkKeys(fj[k], at, {"name", "kind"});
        FreeJoint j;
        j.name = scalar(required(fj[k], at, "name"), at + ".name");
        const std::string kind = scalar(required(fj[k], at, "kind"), at + ".kind");
        if (kind == "robot_base")
          j.kind = FreeJointKind::kRobotBase;
        else if (kind == "object")
          j.kind = FreeJointKind::kObject;
        else
          fail(at + ".kind", "unknown free joint kind '" + kind + "'; valid kinds: robot_base, object", fj[k]["kind"]);
        b.free_joints.push_back(j);
      }
    }
    return b;
  }

  Group parseGroup(const YAML::Node& n) const {
    if (!n.IsMap()) fail("group", "expected a mapping with keys type, axis, order", n);
    checkKeys(n, "group", {"type", "axis", "order"});
    Group g;
    const std::string type = scalar(required(n, "group", "type"), "group.type");
    if (type == "reflection") {
      g.type = GroupType::kReflection;
    } else if (type == "rotation") {
      g.type = GroupType::kRotation;
    } else {
      fail("group.type", "unknown group type '" + type + "'; valid types: reflection, rotation", n["type"]);
    }
    const std::string axis = scalar(required(n, "group", "axis"), "group.axis");
    if (axis == "x") {
      g.axis = Axis::kX;
    } else if (axis == "y") {
      g.axis = Axis::kY;
    } else if (axis == "z") {
      g.axis = Axis::kZ;
    } else {
      fail("group.axis", "unknown axis '" + axis + "'; valid axes: x, y, z", n["axis"]);
    }
    const YAML::Node order = n["order"];
    if (g.type == GroupType::kReflection) {
      g.order = 2;
      if (order.IsDefined() && integer(order, "group.order") != 2)
        fail("group.order", "a reflection has order 2 (omit the key or write 2)", order);
    } else {
      g.order = integer(required(n, "group", "order"), "group.order");
      if (g.order < 2)
        fail("group.order", "a rotation group needs order N >= 2, got " + std::to_string(g.order), order);
    }
    return g;
  }

  BlockLayout parseBlock(const YAML::Node& n, const std::string& path, const Group& g) const {
    if (!n.IsMap()) fail(path, "expected a mapping with keys central, limb", n);
    checkKeys(n, path, {"central", "limb"});
    BlockLayout layout;
    layout.central = parseEntries(n["central"], child(path, "central"), g, /*limb=*/false);
    layout.limb = parseEntries(n["limb"], child(path, "limb"), g, /*limb=*/true);
    if (layout.centralDim() + g.order * layout.limbDim() == 0)
      fail(path, "declares no dimensions (both central and limb are empty)", n);
    return layout;
  }

  std::vector<Entry> parseEntries(const YAML::Node& n, const std::string& path, const Group& g, bool limb) const {
    std::vector<Entry> entries;
    if (!n.IsDefined() || n.IsNull()) return entries;
    if (!n.IsSequence()) fail(path, "expected a list of entries {name: ..., kind: ...}", n);
    std::map<std::string, int> index_of;
    int offset = 0;
    for (std::size_t j = 0; j < n.size(); ++j) {
      const std::string at = path + "[" + std::to_string(j) + "]";
      Entry e = parseEntry(n[j], at, g, limb);
      if (auto [it, fresh] = index_of.emplace(e.name, static_cast<int>(j)); !fresh)
        fail(child(at, "name"),
             "duplicate name '" + e.name + "' (also " + path + "[" + std::to_string(it->second) + "])", n[j]);
      e.offset = offset;
      offset += e.size();
      entries.push_back(std::move(e));
    }
    resolveSwaps(entries, n, path);
    return entries;
  }

  Entry parseEntry(const YAML::Node& n, const std::string& at, const Group& g, bool limb) const {
    if (!n.IsMap()) fail(at, "expected a mapping {name: ..., kind: ...}", n);
    checkKeys(n, at, {"name", "kind", "count", "limb_signs", "swap_with"});
    Entry e;
    e.name = identifier(required(n, at, "name"), child(at, "name"));

    const std::string kind_key = child(at, "kind");
    const std::string kind_name = scalar(required(n, at, "kind"), kind_key);
    const auto kind = entryKindFromName(kind_name);
    if (!kind) fail(kind_key, "unknown kind '" + kind_name + "'; valid kinds: " + validEntryKindNames(), n["kind"]);
    e.kind = *kind;
    if (const std::string why = kindUnsupportedReason(e.kind, g); !why.empty()) fail(kind_key, why, n["kind"]);

    if (const YAML::Node c = n["count"]; c.IsDefined()) {
      e.count = integer(c, child(at, "count"));
      if (entryKindSize(e.kind) != 1)
        fail(child(at, "count"),
             "count repeats 1-D kinds only; '" + kind_name + "' has " + std::to_string(entryKindSize(e.kind)) +
                 " values per instance, write one entry per " + kind_name,
             c);
      if (e.count < 1) fail(child(at, "count"), "count must be >= 1, got " + std::to_string(e.count), c);
    }

    if (const YAML::Node s = n["limb_signs"]; s.IsDefined()) {
      const std::string key = child(at, "limb_signs");
      if (!limb) fail(key, "only limb entries have limb_signs (central entries are not repeated per limb)", s);
      if (!s.IsSequence() || static_cast<int>(s.size()) != g.order)
        fail(key, "expected a list of N = " + std::to_string(g.order) + " signs (+1 or -1), one per limb", s);
      for (std::size_t k = 0; k < s.size(); ++k) {
        const std::string sign_key = key + "[" + std::to_string(k) + "]";
        const int v = integer(s[k], sign_key);
        if (v != 1 && v != -1) fail(sign_key, "a sign is +1 or -1, got " + std::to_string(v), s[k]);
        e.limb_signs.push_back(v);
      }
    }

    if (const YAML::Node w = n["swap_with"]; w.IsDefined()) {
      const std::string key = child(at, "swap_with");
      if (limb) fail(key, "only central entries have swap_with (limb blocks are already swapped by the group)", w);
      if (g.type != GroupType::kReflection)
        fail(key, "swap_with pairs entries under a reflection; a rotation of order N > 2 has no pairwise swap", w);
      if (entryKindSize(e.kind) != 1)
        fail(key, "swap_with pairs 1-D entries only; '" + kind_name + "' has " + std::to_string(entryKindSize(e.kind)) +
                      " values", w);
      e.swap_with = identifier(w, key);
      if (e.swap_with == e.name) fail(key, "an entry cannot swap with itself (use kind 'odd' or 'invariant')", w);
    }
    return e;
  }

  // A pair may be declared on one entry or on both; either way both entries name each other after
  // this, and the compiler reads the partner from either side.
  void resolveSwaps(std::vector<Entry>& entries, const YAML::Node& n, const std::string& path) const {
    auto find = [&](const std::string& name) -> int {
      for (std::size_t j = 0; j < entries.size(); ++j)
        if (entries[j].name == name) return static_cast<int>(j);
      return -1;
    };
    std::vector<std::string> partner(entries.size());
    for (std::size_t j = 0; j < entries.size(); ++j) {
      const Entry& a = entries[j];
      if (a.swap_with.empty()) continue;
      const std::string key = path + "[" + std::to_string(j) + "].swap_with";
      const YAML::Node where = n[j]["swap_with"];
      const int b = find(a.swap_with);
      if (b < 0) fail(key, "no entry named '" + a.swap_with + "' in " + path, where);
      const Entry& p = entries[b];
      if (!p.swap_with.empty() && p.swap_with != a.name)
        fail(key, "'" + a.swap_with + "' swaps with '" + p.swap_with + "', not with '" + a.name + "'", where);
      if (p.kind != a.kind)
        fail(key, "partner '" + p.name + "' has kind '" + entryKindName(p.kind) + "', this entry '" +
                      entryKindName(a.kind) + "'; swapped entries must have the same kind",
             where);
      if (p.count != a.count)
        fail(key, "partner '" + p.name + "' has count " + std::to_string(p.count) + ", this entry " +
                      std::to_string(a.count) + "; swapped entries must have the same count",
             where);
      auto pair = [&](int x, int y) {
        if (!partner[x].empty() && partner[x] != entries[y].name)
          fail(key, "'" + entries[x].name + "' is already paired with '" + partner[x] + "'", where);
        partner[x] = entries[y].name;
      };
      pair(static_cast<int>(j), b);
      pair(b, static_cast<int>(j));
    }
    for (std::size_t j = 0; j < entries.size(); ++j) entries[j].swap_with = partner[j];
  }

  const std::string& src_;
};

}  // namespace

ParsedSpec parseSpecYaml(const YAML::Node& root, const std::string& source) { return Parser(source).parse(root); }

}  // namespace masa::sym
