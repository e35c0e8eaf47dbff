// What actors and the learner need of a transport: typed and raw publish/subscribe on named
// channels and a bounded wait that runs the handlers, with every rejected message counted. Three
// implementations: Transport (LCM, between processes or through memq://, every message encoded,
// authenticated with a key or a signer, decoded through the wire guard), LocalBus (one process,
// a typed message handed to typed subscribers as it is, with no encoding) and LogBus (a LocalBus
// that replays an lcm-logger recording, read-only).
//
// A channel given to subscribe is a regular expression matched against the whole channel name, as
// LCM does. Threading: publish may be called from any thread; handle*() and (un)subscribe() from
// one thread (handlers run on the thread that calls handle*()).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <typeinfo>

#include "common/transport/reject_log.hpp"
#include "common/transport/wire_guard.hpp"

namespace masa::transport {

class MessageBus {
 public:
  using RawHandler = std::function<void(const void* data, int size)>;
  using SubscriptionId = int;

  virtual ~MessageBus() = default;

  // Returns false when the message could not be sent.
  template <class Msg>
  bool publish(const std::string& channel, const Msg& msg) {
    return publishMessage(channel, OutgoingMessage::of(msg));
  }
  // Encoded bytes of a message.
  virtual bool publishRaw(const std::string& channel, const void* data, int size) = 0;

  // Raw bytes, for handlers that decode into a reused message or only measure them; a handler
  // that decodes must do so with decodeChecked().
  virtual SubscriptionId subscribeRaw(const std::string& channel, RawHandler handler) = 0;
  // Decoded messages: bytes pass the wire guard first (decodeChecked); a rejected message is
  // counted under its channel and reason (rejected()) and skipped.
  template <class Msg>
  SubscriptionId subscribe(const std::string& channel, std::function<void(const Msg&)> handler) {
    return subscribeMessage(channel, MessageHandler::of<Msg>(std::move(handler)));
  }
  virtual void unsubscribe(SubscriptionId id) = 0;

  // Dispatches at most one message, waiting up to timeout_ms: >0 handled, 0 timed out, <0 error.
  virtual int handleTimeout(int timeout_ms) = 0;
  // Dispatches every message already queued (without waiting); returns how many.
  virtual int drain() = 0;

  // Messages rejected before their handler: on all channels, and on one per reason.
  int64_t decodeErrors() const { return rejects_.total(); }
  WireRejects rejected(const std::string& channel) const { return rejects_.of(channel); }
  // Every channel's rejects by reason in one line, or "none": what a process says when it stops.
  std::string rejectSummary() const { return rejects_.summary(); }

 protected:
  // A typed message with its type erased: what publish hands an implementation, which either
  // encodes it or keeps a copy.
  struct OutgoingMessage {
    const void* msg;
    const std::type_info* type;
    int (*encoded_size)(const void* msg);
    bool (*encode)(const void* msg, void* buf, int size);  // exactly `size` bytes
    std::shared_ptr<const void> (*copy)(const void* msg);

    template <class Msg>
    static OutgoingMessage of(const Msg& m) {
      return {&m, &typeid(Msg), [](const void* p) { return static_cast<const Msg*>(p)->getEncodedSize(); },
              [](const void* p, void* buf, int size) { return static_cast<const Msg*>(p)->encode(buf, 0, size) == size; },
              [](const void* p) -> std::shared_ptr<const void> { return std::make_shared<Msg>(*static_cast<const Msg*>(p)); }};
    }
  };
  // A typed subscriber with its type erased: it takes a message of `type` as it is, or bytes
  // through decodeChecked (returning the guard's verdict; the handler runs only on kOk).
  struct MessageHandler {
    const std::type_info* type;
    std::function<void(const void* msg)> take;
    std::function<WireVerdict(const void* data, int size)> decode_and_take;

    template <class Msg>
    static MessageHandler of(std::function<void(const Msg&)> handler) {
      auto h = std::make_shared<std::function<void(const Msg&)>>(std::move(handler));
      return {&typeid(Msg), [h](const void* msg) { (*h)(*static_cast<const Msg*>(msg)); },
              [h](const void* data, int size) {
                // A fresh message each time: the generated decoder leaves zero-length arrays
                // untouched, so a reused one could keep stale contents.
                Msg msg;
                const WireVerdict verdict = decodeChecked(data, size, msg);
                if (verdict == WireVerdict::kOk) (*h)(msg);
                return verdict;
              }};
    }
  };

  virtual bool publishMessage(const std::string& channel, const OutgoingMessage& msg) = 0;
  virtual SubscriptionId subscribeMessage(const std::string& channel, MessageHandler handler) = 0;

  RejectLog rejects_;
};

}  // namespace masa::transport
