#include "common/transport/roster.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include <openssl/evp.h>

#include "common/integrity/owned_file.hpp"
#include "common/transport/channels.hpp"

namespace masa::transport {

namespace {

int hexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::runtime_error rosterError(const std::string& source, int line, const std::string& what) {
  std::string where = "roster " + source;
  if (line > 0) {
    where += ':';
    where += std::to_string(line);
  }
  return std::runtime_error(where + ": " + what);
}

}  // namespace

std::string_view roleName(Role role) {
  switch (role) {
    case Role::kLearner: return "learner";
    case Role::kActor: return "actor";
    case Role::kRunner: return "runner";
    case Role::kRobot: return "robot";
  }
  return "";
}

bool parseRole(std::string_view name, Role& role) {
  for (Role r : {Role::kLearner, Role::kActor, Role::kRunner, Role::kRobot}) {
    if (roleName(r) == name) {
      role = r;
      return true;
    }
  }
  return false;
}

bool isRole(uint8_t value) { return value >= 1 && value <= 4; }

std::string SenderId::name() const { return std::string(roleName(role)) + " " + std::to_string(index); }

std::vector<std::string> defaultChannels(Role role) {
  switch (role) {
    case Role::kLearner: return {kPolicyChannel, kLearnerStatsChannel};
    case Role::kActor: return {kRolloutChannel, kHeartbeatChannel};
    case Role::kRunner: return {kRobotCommandChannel};
    case Role::kRobot: return {kRobotStateChannel};
  }
  return {};
}

void Roster::add(SenderId id, const integrity::PublicKeyBytes& key, std::vector<std::string> channels) {
  if (find(id)) throw std::invalid_argument(id.name() + " is in the roster twice");
  EVP_PKEY* pkey = EVP_PKEY_new_raw_public_key(EVP_PKEY_ED25519, nullptr, key.data(), key.size());
  if (pkey == nullptr) throw std::invalid_argument(id.name() + ": not an Ed25519 public key");
  Entry e;
  e.id = id;
  e.key = key;
  e.channels = std::move(channels);
  e.verifier = std::shared_ptr<void>(pkey, [](void* p) { EVP_PKEY_free(static_cast<EVP_PKEY*>(p)); });
  entries_.push_back(std::move(e));
}

Roster Roster::withoutActorsFrom(uint32_t actors, std::vector<SenderId>& retired) const {
  Roster kept(source_);
  for (const Entry& e : entries_) {
    if (e.id.role == Role::kActor && e.id.index >= actors) retired.push_back(e.id);
    else kept.entries_.push_back(e);
  }
  return kept;
}

const Roster::Entry* Roster::find(SenderId id) const {
  for (const Entry& e : entries_)
    if (e.id == id) return &e;
  return nullptr;
}

bool Roster::permits(const Entry& entry, std::string_view channel) {
  return std::find(entry.channels.begin(), entry.channels.end(), channel) != entry.channels.end();
}

std::string Roster::format() const {
  std::string out = "# masa roster: <role> <index> <Ed25519 public key> <channels it may publish on>\n";
  static constexpr char kDigits[] = "0123456789abcdef";
  for (const Entry& e : entries_) {
    out += std::string(roleName(e.id.role)) + " " + std::to_string(e.id.index) + " ";
    for (uint8_t b : e.key) {
      out += kDigits[b >> 4];
      out += kDigits[b & 15];
    }
    out += ' ';
    for (std::size_t i = 0; i < e.channels.size(); ++i) out += (i ? "," : "") + e.channels[i];
    out += '\n';
  }
  return out;
}

Roster Roster::parse(std::string_view text, const std::string& source) {
  Roster roster;
  roster.source_ = source;
  std::istringstream in{std::string(text)};
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    std::string role_name, index_text, key_text, channels_text, extra;
    if (!(words >> role_name)) continue;  // blank or comment
    if (!(words >> index_text >> key_text >> channels_text) || (words >> extra))
      throw rosterError(source, line_no, "expected '<role> <index> <public key> <channels>', got '" + line + "'");
    Role role{};
    if (!parseRole(role_name, role))
      throw rosterError(source, line_no, "unknown role '" + role_name + "' (learner, actor, runner, robot)");
    if (index_text.empty() || index_text.size() > 9 ||
        !std::all_of(index_text.begin(), index_text.end(), [](char c) { return c >= '0' && c <= '9'; }))
      throw rosterError(source, line_no, "index '" + index_text + "' is not a number below 10^9");
    if (key_text.size() != 64) throw rosterError(source, line_no, "the public key is not 64 hex digits");
    integrity::PublicKeyBytes key{};
    for (int i = 0; i < 32; ++i) {
      const int hi = hexValue(key_text[2 * i]), lo = hexValue(key_text[2 * i + 1]);
      if (hi < 0 || lo < 0) throw rosterError(source, line_no, "the public key is not 64 hex digits");
      key[i] = static_cast<uint8_t>(hi << 4 | lo);
    }
    std::vector<std::string> channels;
    std::istringstream list(channels_text);
    for (std::string c; std::getline(list, c, ',');) {
      if (c.empty()) throw rosterError(source, line_no, "an empty channel name in '" + channels_text + "'");
      channels.push_back(c);
    }
    try {
      roster.add({role, static_cast<uint32_t>(std::stoul(index_text))}, key, std::move(channels));
    } catch (const std::invalid_argument& e) {
      throw rosterError(source, line_no, e.what());
    }
  }
  if (roster.entries_.empty()) throw rosterError(source, 0, "lists no sender");
  return roster;
}

Roster Roster::load(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw rosterError(path, 0, "cannot read it (make one with masa_roster)");
  try {
    return parse(integrity::readOwnedFile(path, "roster", integrity::FileSecrecy::kPublic), path);
  } catch (const std::runtime_error& e) {
    if (std::string_view(e.what()).starts_with("roster ")) throw;
    throw rosterError(path, 0, e.what());
  }
}

}  // namespace masa::transport
