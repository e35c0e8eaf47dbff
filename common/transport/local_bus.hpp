// The MessageBus within one process, without LCM: a published message waits in a queue until a
// handle*() call hands it to the subscriptions whose channel pattern matches. A typed message
// reaches the typed subscribers of its type as a copy taken at publish, never encoded; bytes are
// what Transport would deliver: a raw subscriber gets them as they are, a typed one through the
// wire guard (decodeChecked), its rejects counted. So a typed subscriber of another type, or a
// raw one, gets a typed message encoded (once). One that does not encode (Transport's publish
// returns false for it) still reaches the typed subscribers of its type, and no one else. There is
// no key: everything in the process is trusted, as with Transport on memq:// without one.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "common/transport/message_bus.hpp"

namespace masa::transport {

class LocalBus : public MessageBus {
 public:
  LocalBus() = default;
  LocalBus(const LocalBus&) = delete;
  LocalBus& operator=(const LocalBus&) = delete;

  bool publishRaw(const std::string& channel, const void* data, int size) override;
  // Throws std::regex_error for a channel that is not a regular expression.
  SubscriptionId subscribeRaw(const std::string& channel, RawHandler handler) override;
  void unsubscribe(SubscriptionId id) override;
  int handleTimeout(int timeout_ms) override;
  int drain() override;

 protected:
  bool publishMessage(const std::string& channel, const OutgoingMessage& msg) override;
  SubscriptionId subscribeMessage(const std::string& channel, MessageHandler handler) override;

 private:
  struct Pending {
    std::string channel;
    std::shared_ptr<const void> msg;  // a typed message; null for bytes
    OutgoingMessage codec{};          // how to encode msg
    std::optional<std::vector<uint8_t>> bytes;  // given, or msg encoded when first needed
  };
  struct Sub {
    SubscriptionId id;
    std::regex pattern;
    RawHandler raw;                       // a raw subscriber, or
    std::optional<MessageHandler> typed;  // a typed one
    bool removed = false;  // unsubscribed during a dispatch, erased after it
  };

  SubscriptionId add(const std::string& channel, Sub sub);
  void enqueue(Pending p);
  std::optional<Pending> next(int timeout_ms);
  void dispatch(Pending& p);
  // The bytes of p; nullptr when a typed message does not encode (no subscriber gets bytes then).
  const std::vector<uint8_t>* bytesOf(Pending& p);

  std::mutex queue_mutex_;  // publish may come from any thread
  std::condition_variable queued_;
  std::deque<Pending> queue_;
  std::list<Sub> subs_;
  SubscriptionId next_id_ = 0;
  bool dispatching_ = false;
};

}  // namespace masa::transport
