// Signed messages (issue #33, item 2): a key per process, permissions per channel, a counter per
// sender. With a signing identity (Transport(url, SignedMode)), every message on the wire ends in
//
//   [encoded message] ["SIG1"] [role, 1 byte] [index, 4 bytes BE] [counter, 8 bytes BE] [signature, 64 bytes]
//
// where the signature is Ed25519, by the sender's own key, over
//   "MASA-SIG1" || SHA-256("MASA-SIG1" || channel || 0x00 || role || index || counter || message).
// (The message is hashed once with SHA-256 and the 32-byte digest signed: Ed25519 alone would hash
// a 60 KB chunk twice with SHA-512.) A receiver checks, in this order, and refuses at the first
// check that fails, counted under its reason (WireVerdict):
//   - a SIG1 trailer is there, with a role byte of a role ........................ unauthenticated
//   - the roster lists the sender (role, index) ................................... unknown_sender
//   - the roster lets that sender publish on this channel ......................... not_permitted
//   - the message is no longer than its sender's role sends (maxSignedMessageBytes) . over_limit
//     (before any byte is hashed: a forged message of many megabytes costs a lookup, not a hash)
//   - the signature verifies under the roster's key for that sender ................ unauthenticated
//   - what the message claims to be from matches the signer (Transport: an actor's chunks and
//     heartbeats name its own actor id) .............................................. claims_another_sender
//   - the counter is not older than the receiver's start ................................ before_start
//   - the counter is new for (sender, channel): not seen before ...................... replayed
//     and not more than kReplayWindow below the highest seen ........................ beyond_window
// and only a message that passes all of them moves the counter window: nothing a refused message
// carries changes state. A message's counter is the sender's wall clock in microseconds when it
// signed it (one more than its previous counter when the clock has not moved on), so a restarted
// process (same key) starts above its previous life's counters, and a receiver refuses whatever
// was signed before it started (issue #55, item 3): without that, a receiver that restarted took a
// sender's recorded history once, in order, since its empty window accepted any counter.
#pragma once

#include <atomic>
#include <bitset>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <utility>

#include "common/integrity/ed25519_keys.hpp"
#include "common/transport/roster.hpp"
#include "common/transport/wire_guard.hpp"

namespace masa::transport {

inline constexpr uint8_t kSigMarker[4] = {'S', 'I', 'G', '1'};
inline constexpr int kSigMarkerBytes = 4;
inline constexpr int kSigHeaderBytes = kSigMarkerBytes + 1 + 4 + 8;  // marker, role, index, counter
inline constexpr int kSigBytes = 64;
inline constexpr int kSigTrailerBytes = kSigHeaderBytes + kSigBytes;  // 81
// The longest message (before its trailer) a sender of `role` may sign: a robot's state and a
// runner's command are a few hundred bytes a joint (64 KiB: over 1500 joints), a learner's policy
// and an actor's chunk far below 64 MiB.
int64_t maxSignedMessageBytes(Role role);

// How far below the highest counter seen from a sender on a channel a message may still arrive
// (reordered by the network) and be taken once.
inline constexpr int kReplayWindow = 1024;

// Thread-safe: publish() may sign from several threads; each message gets its own counter, the wall
// clock in microseconds or one above the previous counter, whichever is higher.
class MessageSigner {
 public:
  // `first_counter`: the lowest counter it signs with (0: none, the wall clock alone).
  MessageSigner(integrity::SigningKey key, SenderId id, uint64_t first_counter = 0);
  // Reads a private key file (integrity::SigningKey::load) and checks that the roster lists its
  // public key for `id`: throws std::runtime_error otherwise.
  static std::shared_ptr<MessageSigner> load(const std::string& key_path, SenderId id, const Roster& roster);

  // Writes the trailer of the `size` bytes at `message`, for `channel`, to trailer[0, kSigTrailerBytes),
  // with the next counter.
  void seal(std::string_view channel, const void* message, int size, uint8_t* trailer);
  // With a given counter: for tests that replay or reorder.
  void sealWithCounter(std::string_view channel, const void* message, int size, uint64_t counter, uint8_t* trailer) const;

  SenderId id() const { return id_; }
  const integrity::PublicKeyBytes& publicKey() const { return public_; }
  // The lowest counter the next message may get (the clock may give it a higher one).
  uint64_t nextCounter() const { return next_.load(); }

 private:
  integrity::SigningKey key_;
  integrity::PublicKeyBytes public_;
  SenderId id_;
  std::atomic<uint64_t> next_;
};

// Anti-replay window of one (sender, channel): the highest counter taken and which of the
// kReplayWindow below it were taken (bit d: counter top - d), as IPsec's ESP keeps it.
class ReplayWindow {
 public:
  // kOk, kReplayed or kBeyondWindow; changes nothing.
  WireVerdict check(uint64_t counter) const;
  // Records a counter that check() passed.
  void accept(uint64_t counter);

 private:
  bool any_ = false;
  uint64_t top_ = 0;
  std::bitset<kReplayWindow> seen_;
};

// The stateless part of a received message's checks.
struct OpenedMessage {
  WireVerdict verdict = WireVerdict::kUnauthenticated;
  int size = -1;  // the message before its trailer, when verdict is kOk
  SenderId sender;
  uint64_t counter = 0;
};

// One receiver's checks. Not thread-safe: one per Transport, used on its handling thread.
class MessageVerifier {
 public:
  // Refuses counters below `not_before_us` (before_start): the receiver's start on the wall clock;
  // 0 for a receiver of recorded traffic (an LCM log), where every message is from before.
  MessageVerifier(std::shared_ptr<const Roster> roster, uint64_t not_before_us);
  // Trailer, sender, permission and signature; changes nothing.
  OpenedMessage open(std::string_view channel, const void* data, int size) const;
  // The counter against the receiver's start and (sender, channel)'s window; changes nothing.
  WireVerdict fresh(std::string_view channel, const OpenedMessage& m) const;
  // Moves the window: for a message every check passed.
  void accept(std::string_view channel, const OpenedMessage& m);
  const Roster& roster() const { return *roster_; }
  // How many messages open() hashed to check their signature: what a forged message cost.
  int64_t messagesHashed() const { return messages_hashed_; }

 private:
  std::shared_ptr<const Roster> roster_;
  mutable int64_t messages_hashed_ = 0;
  uint64_t not_before_us_;
  std::map<std::pair<SenderId, std::string>, ReplayWindow> windows_;
};

// The sender a SIG1 trailer names, unverified (for tools that watch traffic; never to act on):
// false when `data` does not end in one.
bool peekSigner(const void* data, int size, SenderId& sender, uint64_t& counter);

}  // namespace masa::transport
