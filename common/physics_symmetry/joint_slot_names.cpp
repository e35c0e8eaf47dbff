#include "common/physics_symmetry/joint_slot_names.hpp"

#include <algorithm>
#include <cctype>
#include <set>

namespace masa::task {
namespace {

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out(1);
  for (char c : s) {
    if (c == sep) out.emplace_back();
    else out.back() += c;
  }
  return out;
}

// Keeps the '_'-separated tokens that every name shares at the same place.
std::string commonTokens(const std::vector<std::string>& names) {
  std::vector<std::vector<std::string>> tokens;
  for (const auto& n : names) tokens.push_back(split(n, '_'));
  for (const auto& t : tokens)
    if (t.size() != tokens[0].size()) return "";
  std::string out;
  for (size_t i = 0; i < tokens[0].size(); ++i) {
    bool same = true;
    for (const auto& t : tokens) same = same && t[i] == tokens[0][i];
    if (same && !tokens[0][i].empty()) out += (out.empty() ? "" : "_") + tokens[0][i];
  }
  return out;
}

// Keeps the characters every name shares at the same place (equal lengths), else the common prefix
// and suffix.
std::string commonCharacters(const std::vector<std::string>& names) {
  bool equal_length = true;
  for (const auto& n : names) equal_length = equal_length && n.size() == names[0].size();
  std::string out;
  if (equal_length) {
    for (size_t i = 0; i < names[0].size(); ++i) {
      bool same = true;
      for (const auto& n : names) same = same && n[i] == names[0][i];
      if (same) out += names[0][i];
    }
    return out;
  }
  size_t prefix = 0, suffix = 0, shortest = names[0].size();
  for (const auto& n : names) shortest = std::min(shortest, n.size());
  auto samePrefix = [&](size_t k) {
    for (const auto& n : names) if (n[k] != names[0][k]) return false;
    return true;
  };
  auto sameSuffix = [&](size_t k) {
    for (const auto& n : names) if (n[n.size() - 1 - k] != names[0][names[0].size() - 1 - k]) return false;
    return true;
  };
  while (prefix < shortest && samePrefix(prefix)) ++prefix;
  while (suffix < shortest - prefix && sameSuffix(suffix)) ++suffix;
  return names[0].substr(0, prefix) + names[0].substr(names[0].size() - suffix);
}

}  // namespace

std::string identifier(const std::string& text) {
  std::string out;
  for (char c : text) {
    const bool ok = std::isalnum(static_cast<unsigned char>(c)) || c == '_';
    const char w = ok ? c : '_';
    if (w == '_' && (out.empty() || out.back() == '_')) continue;  // no leading or doubled '_'
    out += w;
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  if (!out.empty() && std::isdigit(static_cast<unsigned char>(out[0]))) out = "j" + out;
  return out;
}

std::vector<std::string> slotNames(const std::vector<std::vector<std::string>>& names_per_slot) {
  const size_t n = names_per_slot.size();
  std::vector<std::string> out(n);
  for (size_t s = 0; s < n; ++s) out[s] = identifier(commonTokens(names_per_slot[s]));
  // A name that is empty or shared falls back to characters, then to its index.
  auto clashes = [&](size_t s) {
    if (out[s].empty()) return true;
    for (size_t t = 0; t < n; ++t)
      if (t != s && out[t] == out[s]) return true;
    return false;
  };
  std::vector<size_t> redo;
  for (size_t s = 0; s < n; ++s)
    if (clashes(s)) redo.push_back(s);
  // Each fallback renames every slot that still clashes at once, so that slots alike stay named alike.
  auto fallBack = [&](auto name_of) {
    std::vector<size_t> still;
    for (size_t s : redo)
      if (clashes(s)) still.push_back(s);
    for (size_t s : still) out[s] = name_of(s);
    redo = still;
  };
  for (size_t s : redo) out[s] = identifier(commonCharacters(names_per_slot[s]));
  fallBack([&](size_t s) { return identifier(names_per_slot[s][0]); });  // limb 0's own name
  fallBack([&](size_t s) { return "joint" + std::to_string(s); });
  return out;
}

int sideOfName(const std::string& name) {
  std::string lower;
  for (char c : name) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  std::string token;
  std::vector<std::string> tokens;
  for (char c : lower + "_") {
    if (std::isalpha(static_cast<unsigned char>(c))) {
      token += c;
    } else if (!token.empty()) {
      tokens.push_back(token);
      token.clear();
    }
  }
  for (const auto& t : tokens) {
    if (t == "right" || t == "r") return 1;
    if (t == "left" || t == "l") return -1;
    // Legged robots' leg codes: FR, RL, HR (front, rear, hind, middle, back) + side.
    if (t.size() == 2 && std::string("frhmb").find(t[0]) != std::string::npos) {
      if (t[1] == 'r') return 1;
      if (t[1] == 'l') return -1;
    }
  }
  return 0;
}

std::optional<std::vector<int>> limbNumbers(const std::vector<std::string>& names) {
  std::vector<std::vector<int>> runs;  // the digit runs of each name, in order
  for (const auto& n : names) {
    std::vector<int> r;
    std::string digits;
    for (char c : n + " ") {
      if (std::isdigit(static_cast<unsigned char>(c))) {
        digits += c;
      } else if (!digits.empty()) {
        r.push_back(digits.size() > 6 ? -1 : std::stoi(digits));
        digits.clear();
      }
    }
    runs.push_back(r);
  }
  for (const auto& r : runs)
    if (r.size() != runs[0].size()) return std::nullopt;
  for (size_t k = 0; k < runs[0].size(); ++k) {
    std::vector<int> values;
    for (const auto& r : runs) values.push_back(r[k]);
    if (std::set<int>(values.begin(), values.end()).size() == values.size() &&
        std::find(values.begin(), values.end(), -1) == values.end())
      return values;
  }
  return std::nullopt;
}

}  // namespace masa::task
