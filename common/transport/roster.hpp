// A run's roster: who may publish what (issue #33, item 2). Each process of a signed run has its own
// Ed25519 key (common/integrity/ed25519_keys.hpp); the roster lists every sender of the run, its
// public key and the channels it may publish on. A receiver believes a message only when its
// trailer names a sender of the roster, the sender may publish on the message's channel, and the
// signature verifies under that sender's key (message_sign.hpp).
//
// On disk, RUN_DIR/roster: one sender per line, '#' comments,
//
//   <role> <index> <public key: 64 hex digits> <channel>[,<channel>...]
//   learner 0 3b6a27bc...  MASA_POLICY,MASA_LEARNER_STATS
//   actor 0   d75a9801...  MASA_ROLLOUT,MASA_ACTOR_HEARTBEAT
//
// made by masa_roster (tools/roster.cpp; deploy/train.sh runs it), public and carried to every
// host beside the process's own private key. Whoever writes it decides who is believed, so it is
// read only when the user running masa (or root) owns it and its directory and nobody else may
// write either, from the very file checked (integrity::readOwnedFile; issue #55, item 4).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "common/integrity/ed25519_keys.hpp"

namespace masa::transport {

enum class Role : uint8_t { kLearner = 1, kActor = 2, kRunner = 3, kRobot = 4 };
// "learner", "actor", "runner" (deploy's policy runner), "robot"; nullopt-like empty for others.
std::string_view roleName(Role role);
// The role of a name; false when the name is none of them.
bool parseRole(std::string_view name, Role& role);
// Whether the byte is a role's number (a received trailer's role byte is hostile).
bool isRole(uint8_t value);

struct SenderId {
  Role role = Role::kActor;
  uint32_t index = 0;
  bool operator==(const SenderId&) const = default;
  auto operator<=>(const SenderId&) const = default;
  std::string name() const;  // "actor 3"
};

// The channels a role publishes in a training run or on a robot, as masa_roster writes them.
std::vector<std::string> defaultChannels(Role role);

class Roster {
 public:
  Roster() = default;
  // An empty roster that errors name as `source` (one built in memory, e.g. an MPI job's).
  explicit Roster(std::string source) : source_(std::move(source)) {}
  struct Entry {
    SenderId id;
    integrity::PublicKeyBytes key{};
    std::vector<std::string> channels;  // the channels it may publish on
    std::shared_ptr<void> verifier;     // the key parsed once for OpenSSL (message_sign.cpp)
  };

  // Reads a roster file; throws std::runtime_error naming the file and line when it is missing,
  // owned by another user, writable by others than its owner, in a directory others own or may
  // write (integrity::readOwnedFile), or malformed (an unknown role, a key that is not 64 hex
  // digits, no channel, a sender twice).
  static Roster load(const std::string& path);
  static Roster parse(std::string_view text, const std::string& source);

  // Adds a sender; throws std::invalid_argument when it is there already.
  void add(SenderId id, const integrity::PublicKeyBytes& key, std::vector<std::string> channels);
  // The sender's entry, or nullptr when the roster does not list it.
  const Entry* find(SenderId id) const;
  static bool permits(const Entry& entry, std::string_view channel);
  // The roster without the actors of index `actors` and above, whose ids go to `retired` (a run
  // resumed with fewer actors: the others leave it, so that their recorded chunks, and their
  // hosts that still hold their keys, are refused as unknown senders; issue #55, item 3).
  Roster withoutActorsFrom(uint32_t actors, std::vector<SenderId>& retired) const;
  const std::vector<Entry>& entries() const { return entries_; }
  const std::string& source() const { return source_; }
  // The file's text: what load() reads back.
  std::string format() const;

 private:
  std::vector<Entry> entries_;
  std::string source_;
};

}  // namespace masa::transport
