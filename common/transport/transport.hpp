// The one door to LCM, the MessageBus between processes (message_bus.hpp): a lcm::LCM on a
// provider URL (udpm:// multicast, memq:// in-process for tests, tcpq:// through a hub where
// multicast is not routed, file:// to replay a log), with typed publish/subscribe and a bounded
// wait. Nothing above this layer includes lcm-cpp.hpp; LocalBus (local_bus.hpp) is the other
// implementation, for one process.
//
// With a run key, it authenticates every message (message_auth.hpp): publishing appends the
// key's trailer, and a received message without a valid one is counted (kUnauthenticated) and
// never reaches a handler; the others reach it without their trailer, byte for byte as published.
// Without a key, bytes pass unchanged both ways (in-process memq runs, robot channels, --no-auth).
// With a signing identity (SignedMode: this process's key and the run's roster, message_sign.hpp),
// publishing appends a SIG1 trailer (sender, counter, Ed25519 signature), and a received message
// reaches handlers only when the roster lists its sender, lets it publish on the channel, its
// signature verifies, an actor's chunk or heartbeat names that actor, and its counter is new;
// otherwise it is counted under the first reason it fails. Threading: as MessageBus says.
#pragma once

#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "common/transport/lcm_url.hpp"
#include "common/transport/message_auth.hpp"
#include "common/transport/message_bus.hpp"
#include "common/transport/message_sign.hpp"
#include "common/transport/run_key.hpp"
#include "common/transport/wire_guard.hpp"

namespace lcm {
class LCM;
}  // namespace lcm
struct _lcm_subscription_t;

namespace masa::transport {

// Microseconds since the Unix epoch (the utime fields of the messages).
int64_t wallClockMicros();

// Messages LCM keeps queued per subscription between handle calls; past it, LCM drops them
// silently. LCM's default, 30, lost rollout chunks whenever the learner was busy with an update
// (about 15% of them in a 2-actor run on this machine); 2048 chunks of 60 KB are about 120 MB.
inline constexpr int kSubscriptionQueueCapacity = 2048;

// Whose rollout chunks a receiver takes (issue #55, item 3): in an MPI job actor i reports to
// learner rank i mod ranks, and each rank takes only its own share. Without it, a chunk signed for
// rank 1 and copied to rank 0's URL verified there (the signature names the channel, not the rank)
// and was taken as current data.
struct ActorShare {
  uint32_t rank = 0, ranks = 1;  // ranks 1: every actor
  bool takes(uint32_t actor) const { return ranks <= 1 || actor % ranks == rank; }
};

// A process's signing identity in a signed run: its signer (shared by the process's transports,
// so that its counter runs over all of them), the run's roster, and the actors whose rollouts it takes.
struct SignedMode {
  std::shared_ptr<MessageSigner> signer;
  std::shared_ptr<const Roster> roster;
  ActorShare rollout_share;
};

// The roster file and this process's private key file (never the key itself on a command line):
// throws std::runtime_error naming the file when either is refused, or the roster gives `id`
// another key.
SignedMode loadSignedMode(const std::string& roster_path, const std::string& key_path, SenderId id);

class Transport : public MessageBus {
 public:
  // "" uses LCM_DEFAULT_URL (or LCM's own default). Throws std::runtime_error when LCM cannot
  // start on the URL. For a udpm URL, warns on stderr when net.core.rmem_max is below the
  // requested recv_buf_size (see recvBufCheck()). With `key`, every message is authenticated.
  explicit Transport(const std::string& url, const std::optional<RunKey>& key = std::nullopt);
  // Signed: throws std::invalid_argument without a roster. Without a signer it only watches: every
  // message is verified against the roster, and publishing throws std::logic_error.
  Transport(const std::string& url, const SignedMode& mode);
  ~Transport() override;
  Transport(const Transport&) = delete;
  Transport& operator=(const Transport&) = delete;

  const std::string& url() const { return url_; }
  const RecvBufCheck& recvBufCheck() const { return recv_buf_; }
  bool authenticates() const { return auth_ != nullptr || verifier_ != nullptr; }
  bool signs() const { return signer_ != nullptr; }
  // In a handler of a signed transport: the verified sender of the message being handled.
  const std::optional<SenderId>& currentSender() const { return current_sender_; }

  // publish<Msg> encodes into a reused buffer, appends the run key's trailer (with a key) and
  // publishes; returns false when LCM reports a failure. publishRaw does the same for encoded bytes.
  bool publishRaw(const std::string& channel, const void* data, int size) override;
  // The bytes exactly as given, with no trailer even with a key: what any machine on the LAN can
  // send. For tests and tools that forge or replay traffic.
  bool publishWire(const std::string& channel, const void* data, int size);

  // Raw bytes (rollout chunks: see RolloutAssembler::acceptEncoded). Throws std::runtime_error
  // when LCM cannot subscribe (udpm: its self test failed, e.g. a firewall drops the process's own
  // multicast), rather than leaving a subscription that never receives anything. A message
  // without a valid tag (with a key) or signature (signed) is counted and never reaches a handler.
  SubscriptionId subscribeRaw(const std::string& channel, RawHandler handler) override;
  void unsubscribe(SubscriptionId id) override;

  int handleTimeout(int timeout_ms) override;
  int drain() override;

 protected:
  bool publishMessage(const std::string& channel, const OutgoingMessage& msg) override;
  SubscriptionId subscribeMessage(const std::string& channel, MessageHandler handler) override;

 private:
  struct Sub {
    SubscriptionId id;
    RawHandler handler;
    Transport* owner = nullptr;
    _lcm_subscription_t* lcm_sub = nullptr;  // LCM's C API: it reports a failed subscribe
  };

  void deliver(const Sub& sub, const char* channel, const void* data, int size);
  // Signed: every check of message_sign.hpp and the actor-id claim; moves the counter window only
  // for a message that passes them all. One LCM dispatch hands the same bytes to each subscription
  // of the channel: the verdict is kept for the others, which must not see a replay.
  OpenedMessage openSigned(const char* channel, const void* data, int size);
  int lcmHandle(int timeout_ms);
  void countRejected(const std::string& channel, WireVerdict why);
  // The reused publish buffer, with room for `size` bytes and a trailer; the caller holds publish_mutex_.
  // Every sealed publish starts here, so here a watcher's publish is refused (std::logic_error).
  uint8_t* publishBuffer(int size);
  // Seals the first `size` bytes of the publish buffer (with a key) and publishes them.
  bool sendPublishBuffer(const std::string& channel, int size);

  std::string url_;
  RecvBufCheck recv_buf_;
  std::unique_ptr<lcm::LCM> lcm_;
  std::list<Sub> subs_;  // stable addresses: LCM keeps a pointer to each
  SubscriptionId next_id_ = 0;
  std::unique_ptr<MessageAuthenticator> auth_;  // null: no key
  std::string key_id_;                           // RunKey::id(), for the warnings
  std::shared_ptr<MessageSigner> signer_;     // null: not signed
  std::unique_ptr<MessageVerifier> verifier_;  // signed runs (with signer_, or alone for a watcher)
  ActorShare rollout_share_;
  std::optional<SenderId> current_sender_;
  uint64_t dispatch_ = 0;  // LCM dispatches so far (handleTimeout, drain)
  struct Verdict {
    uint64_t dispatch = ~uint64_t{0};
    const void* data = nullptr;
    int size = 0;
    OpenedMessage opened;
  } last_verdict_;
  std::mutex publish_mutex_;
  std::vector<uint8_t> publish_buf_;
};

}  // namespace masa::transport
