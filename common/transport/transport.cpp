#include "common/transport/transport.hpp"

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

Transport::~Transport() {
  for (Sub& s : subs_) lcm_unsubscribe(lcm_->getUnderlyingLCM(), s.lcm_sub);
}

bool Transport::publishWire(const std::string& channel, const void* data, int size) {
  return lcm_->publish(channel, data, static_cast<unsigned int>(size)) == 0;
}

bool Transport::publishRaw(const std::string& channel, const void* data, int size) {
  if (!auth_) return publishWire(channel, data, size);
  std::lock_guard<std::mutex> lock(publish_mutex_);
  uint8_t* buf = publishBuffer(size);
  if (size > 0) std::memcpy(buf, data, static_cast<std::size_t>(size));
  return sendPublishBuffer(channel, size);
}

uint8_t* Transport::publishBuffer(int size) {
  const std::size_t needed = static_cast<std::size_t>(size) + (auth_ ? kAuthTrailerBytes : 0);
  if (publish_buf_.size() < needed) publish_buf_.resize(needed);
  return publish_buf_.data();
}

bool Transport::sendPublishBuffer(const std::string& channel, int size) {
  if (auth_) {
    auth_->seal(channel, publish_buf_.data(), size, publish_buf_.data() + size);
    size += kAuthTrailerBytes;
  }
  return publishWire(channel, publish_buf_.data(), size);
}

void Transport::deliver(const Sub& sub, const char* channel, const void* data, int size) {
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

void Transport::unsubscribe(SubscriptionId id) {
  for (auto it = subs_.begin(); it != subs_.end(); ++it) {
    if (it->id == id) {
      lcm_unsubscribe(lcm_->getUnderlyingLCM(), it->lcm_sub);
      subs_.erase(it);
      return;
    }
  }
}

WireRejects Transport::rejected(const std::string& channel) const {
  const auto it = rejects_.find(channel);
  return it == rejects_.end() ? WireRejects{} : it->second.count;
}

std::string Transport::rejectSummary() const {
  std::string out;
  for (const auto& [channel, r] : rejects_) {
    std::string reasons;
    for (int v = 0; v < kNumWireVerdicts; ++v) {
      if (r.count[v] == 0) continue;
      if (!reasons.empty()) reasons += ", ";
      reasons += std::string(wireVerdictName(static_cast<WireVerdict>(v))) + " " + std::to_string(r.count[v]);
    }
    if (reasons.empty()) continue;
    if (!out.empty()) out += "; ";
    out += channel + ": " + reasons;
  }
  return out.empty() ? "none" : out;
}

void Transport::countRejected(const std::string& channel, WireVerdict why) {
  ++decode_errors_;
  ChannelRejects& r = rejects_[channel];
  ++r.count[static_cast<int>(why)];
  ++r.unwarned;
  // At most one line per channel every few seconds: a fuzzer must not fill the log.
  constexpr auto kWarnInterval = std::chrono::seconds(5);
  const auto now = std::chrono::steady_clock::now();
  if (r.warned && now - r.last_warning < kWarnInterval) return;
  int64_t total = 0;
  for (int64_t n : r.count) total += n;
  std::cerr << "masa transport: rejected " << r.unwarned << " message(s) on " << channel << " (latest: "
            << wireVerdictName(why) << "); " << total << " rejected on this channel so far";
  if (why == WireVerdict::kUnauthenticated)
    std::cerr << " (unsigned, or signed with another key: do all processes of the run share its run.key? our key id "
              << key_id_ << ")";
  std::cerr << "\n";
  r.warned = true;
  r.last_warning = now;
  r.unwarned = 0;
}

int Transport::handleTimeout(int timeout_ms) { return lcm_->handleTimeout(timeout_ms); }

int Transport::drain() {
  int n = 0;
  while (lcm_->handleTimeout(0) > 0) ++n;
  return n;
}

}  // namespace masa::transport
