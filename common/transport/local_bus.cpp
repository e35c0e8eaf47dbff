#include "common/transport/local_bus.hpp"

#include <algorithm>
#include <chrono>

namespace masa::transport {

bool LocalBus::publishMessage(const std::string& channel, const OutgoingMessage& msg) {
  Pending p{channel, msg.copy(msg.msg), msg, std::nullopt};
  p.codec.msg = p.msg.get();  // the caller's object may be gone when it is dispatched
  enqueue(std::move(p));
  return true;
}

bool LocalBus::publishRaw(const std::string& channel, const void* data, int size) {
  if (size < 0) return false;
  const auto* bytes = static_cast<const uint8_t*>(data);
  enqueue(Pending{channel, nullptr, {}, std::vector<uint8_t>(bytes, bytes + size)});
  return true;
}

void LocalBus::enqueue(Pending p) {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    queue_.push_back(std::move(p));
  }
  queued_.notify_one();
}

LocalBus::SubscriptionId LocalBus::add(const std::string& channel, Sub sub) {
  // LCM's channel patterns: POSIX extended expressions matched against the whole name.
  sub.pattern = std::regex(channel, std::regex::extended);
  sub.id = next_id_++;
  subs_.push_back(std::move(sub));
  return subs_.back().id;
}

LocalBus::SubscriptionId LocalBus::subscribeRaw(const std::string& channel, RawHandler handler) {
  Sub sub;
  sub.raw = std::move(handler);
  return add(channel, std::move(sub));
}

LocalBus::SubscriptionId LocalBus::subscribeMessage(const std::string& channel, MessageHandler handler) {
  Sub sub;
  sub.typed = std::move(handler);
  return add(channel, std::move(sub));
}

void LocalBus::unsubscribe(SubscriptionId id) {
  for (auto it = subs_.begin(); it != subs_.end(); ++it) {
    if (it->id != id) continue;
    // A handler may unsubscribe itself: its function must outlive the call.
    if (dispatching_)
      it->removed = true;
    else
      subs_.erase(it);
    return;
  }
}

std::optional<LocalBus::Pending> LocalBus::next(int timeout_ms) {
  std::unique_lock<std::mutex> lock(queue_mutex_);
  if (timeout_ms > 0)
    queued_.wait_for(lock, std::chrono::milliseconds(timeout_ms), [this] { return !queue_.empty(); });
  if (queue_.empty()) return std::nullopt;
  Pending p = std::move(queue_.front());
  queue_.pop_front();
  return p;
}

const std::vector<uint8_t>* LocalBus::bytesOf(Pending& p) {
  if (!p.bytes) {
    std::vector<uint8_t> encoded(static_cast<std::size_t>(p.codec.encoded_size(p.msg.get())));
    if (!p.codec.encode(p.msg.get(), encoded.data(), static_cast<int>(encoded.size()))) return nullptr;
    p.bytes = std::move(encoded);
  }
  return &*p.bytes;
}

void LocalBus::dispatch(Pending& p) {
  // The subscriptions as they were when the message arrived: one added by a handler waits for the next.
  std::vector<SubscriptionId> ids;
  for (const Sub& s : subs_)
    if (std::regex_match(p.channel, s.pattern)) ids.push_back(s.id);
  dispatching_ = true;
  for (SubscriptionId id : ids) {
    auto it = std::find_if(subs_.begin(), subs_.end(), [id](const Sub& s) { return s.id == id; });
    if (it == subs_.end() || it->removed) continue;
    if (it->typed && p.msg && *it->typed->type == *p.codec.type) {
      it->typed->take(p.msg.get());
      continue;
    }
    const std::vector<uint8_t>* bytes = bytesOf(p);
    if (bytes == nullptr) continue;
    const int size = static_cast<int>(bytes->size());
    if (!it->typed) {
      it->raw(bytes->data(), size);
      continue;
    }
    const WireVerdict verdict = it->typed->decode_and_take(bytes->data(), size);
    if (verdict != WireVerdict::kOk) rejects_.count(p.channel, verdict);
  }
  dispatching_ = false;
  subs_.remove_if([](const Sub& s) { return s.removed; });
}

int LocalBus::handleTimeout(int timeout_ms) {
  std::optional<Pending> p = next(timeout_ms);
  if (!p) return 0;
  dispatch(*p);
  return 1;
}

int LocalBus::drain() {
  int n = 0;
  while (std::optional<Pending> p = next(0)) {
    dispatch(*p);
    ++n;
  }
  return n;
}

}  // namespace masa::transport
