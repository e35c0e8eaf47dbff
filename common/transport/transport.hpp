// The one door to LCM: a lcm::LCM on a provider URL (udpm:// multicast, memq:// in-process for
// tests, tcpq:// through a hub where multicast is not routed, file:// to replay a log), with typed
// publish/subscribe and a bounded wait. Nothing above this layer includes lcm-cpp.hpp, so the
// transport could be replaced without touching actors or the learner.
//
// With a run key, it authenticates every message (message_auth.hpp): publishing appends the
// key's trailer, and a received message without a valid one is counted (kUnauthenticated) and
// never reaches a handler; the others reach it without their trailer, byte for byte as published.
// Without a key, bytes pass unchanged both ways (in-process memq runs, robot channels, --no-auth).
// With a signing identity (SignedMode: this process's key and the run's roster, message_sign.hpp),
// publishing appends a SIG1 trailer (sender, counter, Ed25519 signature), and a received message
// reaches handlers only when the roster lists its sender, lets it publish on the channel, its
// signature verifies, an actor's chunk or heartbeat names that actor, and its counter is new;
// otherwise it is counted under the first reason it fails.
//
// Threading: publish() may be called from any thread; handle*() and (un)subscribe() from one
// thread (handlers run on the thread that calls handle*()).
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "common/transport/lcm_url.hpp"
#include "common/transport/message_auth.hpp"
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

// A process's signing identity in a signed run: its signer (shared by the process's transports,
// so that its counter runs over all of them) and the run's roster.
struct SignedMode {
  std::shared_ptr<MessageSigner> signer;
  std::shared_ptr<const Roster> roster;
};

// The roster file and this process's private key file (never the key itself on a command line):
// throws std::runtime_error naming the file when either is refused, or the roster gives `id`
// another key.
SignedMode loadSignedMode(const std::string& roster_path, const std::string& key_path, SenderId id);

class Transport {
 public:
  using RawHandler = std::function<void(const void* data, int size)>;
  using SubscriptionId = int;

  // "" uses LCM_DEFAULT_URL (or LCM's own default). Throws std::runtime_error when LCM cannot
  // start on the URL. For a udpm URL, warns on stderr when net.core.rmem_max is below the
  // requested recv_buf_size (see recvBufCheck()). With `key`, every message is authenticated.
  explicit Transport(const std::string& url, const std::optional<RunKey>& key = std::nullopt);
  // Signed: throws std::invalid_argument without a roster. Without a signer it only watches: every
  // message is verified against the roster, and publishing throws std::logic_error.
  Transport(const std::string& url, const SignedMode& mode);
  ~Transport();
  Transport(const Transport&) = delete;
  Transport& operator=(const Transport&) = delete;

  const std::string& url() const { return url_; }
  const RecvBufCheck& recvBufCheck() const { return recv_buf_; }
  bool authenticates() const { return auth_ != nullptr || verifier_ != nullptr; }
  bool signs() const { return signer_ != nullptr; }
  // In a handler of a signed transport: the verified sender of the message being handled.
  const std::optional<SenderId>& currentSender() const { return current_sender_; }

  // Encodes into a reused buffer, appends the run key's trailer (with a key) and publishes;
  // returns false when LCM reports a failure. publishRaw does the same for encoded bytes.
  template <class Msg>
  bool publish(const std::string& channel, const Msg& msg);
  bool publishRaw(const std::string& channel, const void* data, int size);
  // The bytes exactly as given, with no trailer even with a key: what any machine on the LAN can
  // send. For tests and tools that forge or replay traffic.
  bool publishWire(const std::string& channel, const void* data, int size);

  // Raw bytes, for handlers that decode into a reused message (rollout chunks: see
  // RolloutAssembler::acceptEncoded) or only measure them; a handler that decodes must do so with
  // decodeChecked(). Throws std::runtime_error when LCM cannot subscribe (udpm: its self test
  // failed, e.g. a firewall drops the process's own multicast), rather than leaving a
  // subscription that never receives anything.
  SubscriptionId subscribeRaw(const std::string& channel, RawHandler handler);
  // Decoded messages, each through the wire guard first (decodeChecked). A rejected message is
  // counted under its channel and reason (rejected()), warned about at a rate limit, and skipped.
  template <class Msg>
  SubscriptionId subscribe(const std::string& channel, std::function<void(const Msg&)> handler);
  void unsubscribe(SubscriptionId id);

  // Dispatches at most one message, waiting up to timeout_ms: >0 handled, 0 timed out, <0 error.
  int handleTimeout(int timeout_ms);
  // Dispatches every message already queued (without waiting); returns how many.
  int drain();

  // Messages rejected before their handler (no valid tag with a key, or subscribe()'s guard):
  // on all channels, and on one per reason.
  int64_t decodeErrors() const { return decode_errors_; }
  WireRejects rejected(const std::string& channel) const;
  // Every channel's rejects by reason in one line ("MASA_POLICY: malformed 12, unauthenticated 3;
  // ..."), or "none": what a process says when it stops.
  std::string rejectSummary() const;

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
  int64_t decode_errors_ = 0;
  struct ChannelRejects {
    WireRejects count{};
    bool warned = false;
    std::chrono::steady_clock::time_point last_warning{};
    int64_t unwarned = 0;  // rejected since the last warning
  };
  std::map<std::string, ChannelRejects> rejects_;
  std::unique_ptr<MessageAuthenticator> auth_;  // null: no key
  std::string key_id_;                           // RunKey::id(), for the warnings
  std::shared_ptr<MessageSigner> signer_;     // null: not signed
  std::unique_ptr<MessageVerifier> verifier_;  // signed runs (with signer_, or alone for a watcher)
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

template <class Msg>
bool Transport::publish(const std::string& channel, const Msg& msg) {
  std::lock_guard<std::mutex> lock(publish_mutex_);
  const int size = msg.getEncodedSize();
  if (msg.encode(publishBuffer(size), 0, size) != size) return false;
  return sendPublishBuffer(channel, size);
}

template <class Msg>
Transport::SubscriptionId Transport::subscribe(const std::string& channel, std::function<void(const Msg&)> handler) {
  return subscribeRaw(channel, [this, channel, handler = std::move(handler)](const void* data, int size) {
    // A fresh message each time: the generated decoder leaves zero-length arrays untouched, so a
    // reused one could keep stale contents. Only rollout chunks are frequent enough to matter,
    // and they take the raw path.
    Msg msg;
    const WireVerdict verdict = decodeChecked(data, size, msg);
    if (verdict != WireVerdict::kOk) return countRejected(channel, verdict);
    handler(msg);
  });
}

}  // namespace masa::transport
