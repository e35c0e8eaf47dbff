#include "common/transport/transport.hpp"

#include "common/transport/channels.hpp"
#include "masa/lcmt_actor_heartbeat.hpp"
#include "masa/lcmt_rollout_chunk.hpp"

#include <chrono>
#include <cstring>
#include <iostream>
#include <lcm/lcm-cpp.hpp>
#include <stdexcept>

namespace masa::transport {

int64_t wallClockMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

Transport::Transport(const std::string& url, const std::optional<RunKey>& key) : url_(url) {
  if (key) {
    auth_ = std::make_unique<MessageAuthenticator>(*key);
    key_id_ = key->id();
  }
  const int64_t requested = recvBufSizeOf(url);
  if (requested > 0) {
    recv_buf_ = checkRecvBuf(requested);
    if (!recv_buf_.sufficient) std::cerr << "masa transport: warning: " << recv_buf_.message << "\n";
  }
  lcm_ = std::make_unique<lcm::LCM>(url);
  if (!lcm_->good()) {
    throw std::runtime_error("masa transport: LCM failed to start on '" + url +
                             "' (for udpm: is multicast routed? e.g. ip route add 224.0.0.0/4 dev lo)");
  }
}

SignedMode loadSignedMode(const std::string& roster_path, const std::string& key_path, SenderId id) {
  SignedMode mode;
  auto roster = std::make_shared<Roster>(Roster::load(roster_path));
  mode.signer = MessageSigner::load(key_path, id, *roster);
  mode.roster = std::move(roster);
  return mode;
}

Transport::Transport(const std::string& url, const SignedMode& mode) : Transport(url) {
  if (!mode.roster) throw std::invalid_argument("masa transport: signed mode without a roster");
  rollout_share_ = mode.rollout_share;
  signer_ = mode.signer;  // null: a watcher that verifies and never publishes (masa_lcm_probe --roster)
  // A log (file://) is recorded traffic: all of it from before this receiver started.
  const bool recorded = url.rfind("file://", 0) == 0;
  verifier_ = std::make_unique<MessageVerifier>(mode.roster, recorded ? 0 : static_cast<uint64_t>(wallClockMicros()));
}

Transport::~Transport() {
  for (Sub& s : subs_) lcm_unsubscribe(lcm_->getUnderlyingLCM(), s.lcm_sub);
}

bool Transport::publishWire(const std::string& channel, const void* data, int size) {
  return lcm_->publish(channel, data, static_cast<unsigned int>(size)) == 0;
}

bool Transport::publishMessage(const std::string& channel, const OutgoingMessage& msg) {
  std::lock_guard<std::mutex> lock(publish_mutex_);
  const int size = msg.encoded_size(msg.msg);
  if (!msg.encode(msg.msg, publishBuffer(size), size)) return false;
  return sendPublishBuffer(channel, size);
}

bool Transport::publishRaw(const std::string& channel, const void* data, int size) {
  // Unchanged bytes only without any authentication; a watcher goes on to publishBuffer's refusal.
  if (!authenticates()) return publishWire(channel, data, size);
  std::lock_guard<std::mutex> lock(publish_mutex_);
  uint8_t* buf = publishBuffer(size);
  if (size > 0) std::memcpy(buf, data, static_cast<std::size_t>(size));
  return sendPublishBuffer(channel, size);
}

uint8_t* Transport::publishBuffer(int size) {
  if (verifier_ && !signer_) throw std::logic_error("masa transport: a watcher (roster, no signing key) cannot publish");
  const std::size_t needed =
      static_cast<std::size_t>(size) + (signer_ ? kSigTrailerBytes : auth_ ? kAuthTrailerBytes : 0);
  if (publish_buf_.size() < needed) publish_buf_.resize(needed);
  return publish_buf_.data();
}

bool Transport::sendPublishBuffer(const std::string& channel, int size) {
  if (signer_) {
    signer_->seal(channel, publish_buf_.data(), size, publish_buf_.data() + size);
    size += kSigTrailerBytes;
  } else if (auth_) {
    auth_->seal(channel, publish_buf_.data(), size, publish_buf_.data() + size);
    size += kAuthTrailerBytes;
  }
  return publishWire(channel, publish_buf_.data(), size);
}

namespace {

// The channels whose messages name the actor that sends them (lcmt_rollout_chunk and
// lcmt_actor_heartbeat: int32 actor_id after int64 run_id, at byte 16 after the 8-byte hash).
struct ActorClaim {
  const char* channel;
  int64_t hash;
};
const ActorClaim* actorClaimOf(std::string_view channel) {
  static const ActorClaim kClaims[] = {{kRolloutChannel, masa::lcmt_rollout_chunk::getHash()},
                                       {kHeartbeatChannel, masa::lcmt_actor_heartbeat::getHash()}};
  for (const ActorClaim& c : kClaims)
    if (channel == c.channel) return &c;
  return nullptr;
}

int64_t readBigEndian(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = v << 8 | p[i];
  return static_cast<int64_t>(v);
}

// Whether a verified message of `sender` on `channel` claims to be another's: an actor's chunk or
// heartbeat with another actor id, or one of those from a sender that is not an actor. A message
// too short or of another type is left to the wire guard, which refuses it.
bool claimsAnother(std::string_view channel, SenderId sender, const uint8_t* p, int size) {
  const ActorClaim* claim = actorClaimOf(channel);
  if (claim == nullptr) return false;
  if (sender.role != Role::kActor) return true;
  if (size < 20 || readBigEndian(p, 8) != claim->hash) return false;
  return readBigEndian(p + 16, 4) != static_cast<int64_t>(static_cast<int32_t>(sender.index));
}

}  // namespace

OpenedMessage Transport::openSigned(const char* channel, const void* data, int size) {
  if (last_verdict_.dispatch == dispatch_ && last_verdict_.data == data && last_verdict_.size == size)
    return last_verdict_.opened;
  OpenedMessage m = verifier_->open(channel, data, size);
  if (m.verdict == WireVerdict::kOk && claimsAnother(channel, m.sender, static_cast<const uint8_t*>(data), m.size))
    m.verdict = WireVerdict::kClaimsAnotherSender;
  // An actor's chunk is for its own learner rank alone; before the counter, so that it moves no window.
  if (m.verdict == WireVerdict::kOk && std::string_view(channel) == kRolloutChannel &&
      m.sender.role == Role::kActor && !rollout_share_.takes(m.sender.index))
    m.verdict = WireVerdict::kAnotherRanksActor;
  if (m.verdict == WireVerdict::kOk) m.verdict = verifier_->fresh(channel, m);
  if (m.verdict == WireVerdict::kOk) verifier_->accept(channel, m);
  last_verdict_ = {dispatch_, data, size, m};
  return m;
}

void Transport::deliver(const Sub& sub, const char* channel, const void* data, int size) {
  if (verifier_) {
    const OpenedMessage m = openSigned(channel, data, size);
    if (m.verdict != WireVerdict::kOk) return countRejected(channel, m.verdict);
    current_sender_ = m.sender;
    sub.handler(data, m.size);
    current_sender_.reset();
    return;
  }
  if (auth_) {
    // The channel it arrived on, as LCM reports it: the tag must be for this one.
    size = auth_->open(channel, data, size);
    if (size < 0) return countRejected(channel, WireVerdict::kUnauthenticated);
  }
  sub.handler(data, size);
}

Transport::SubscriptionId Transport::subscribeRaw(const std::string& channel, RawHandler handler) {
  Sub& s = subs_.emplace_back();
  s.id = next_id_++;
  s.handler = std::move(handler);
  s.owner = this;
  // The C API, because lcm-cpp hides a failed subscribe behind a Subscription that never fires.
  s.lcm_sub = lcm_subscribe(
      lcm_->getUnderlyingLCM(), channel.c_str(),
      [](const lcm_recv_buf_t* rb, const char* channel, void* user) {
        const Sub& sub = *static_cast<const Sub*>(user);
        sub.owner->deliver(sub, channel, rb->data, static_cast<int>(rb->data_size));
      },
      &s);
  if (s.lcm_sub == nullptr) {
    subs_.pop_back();
    throw std::runtime_error("masa transport: LCM cannot subscribe to " + channel + " on '" + url_ +
                             "' (for udpm: its self test failed, its own multicast did not come back: check the "
                             "multicast route and that no firewall drops it)");
  }
  lcm_subscription_set_queue_capacity(s.lcm_sub, kSubscriptionQueueCapacity);
  return s.id;
}

Transport::SubscriptionId Transport::subscribeMessage(const std::string& channel, MessageHandler handler) {
  return subscribeRaw(channel, [this, channel, handler = std::move(handler)](const void* data, int size) {
    const WireVerdict verdict = handler.decode_and_take(data, size);
    if (verdict != WireVerdict::kOk) countRejected(channel, verdict);
  });
}

void Transport::unsubscribe(SubscriptionId id) {
  for (auto it = subs_.begin(); it != subs_.end(); ++it) {
    if (it->id == id) {
      lcm_unsubscribe(lcm_->getUnderlyingLCM(), it->lcm_sub);
      subs_.erase(it);
      return;
    }
  }
}

void Transport::countRejected(const std::string& channel, WireVerdict why) {
  if (why != WireVerdict::kUnauthenticated) return rejects_.count(channel, why);
  if (verifier_)
    return rejects_.count(channel, why, "unsigned, or a signature that does not verify under the roster's key of the sender it names");
  rejects_.count(channel, why,
                 "unsigned, or signed with another key: do all processes of the run share its run.key? our key id " + key_id_);
}

int Transport::lcmHandle(int timeout_ms) {
  ++dispatch_;  // a new message: its subscriptions may share a verdict, nothing before it may
  return lcm_->handleTimeout(timeout_ms);
}

int Transport::handleTimeout(int timeout_ms) { return lcmHandle(timeout_ms); }

int Transport::drain() {
  int n = 0;
  while (lcmHandle(0) > 0) ++n;
  return n;
}

}  // namespace masa::transport
