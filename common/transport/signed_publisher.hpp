// Signed messages from a process whose own transport does not verify (issue #33, item 2): the
// robot's policy runner (masa_deploy --roster --signing-key) signs its commands as `runner 0` of the
// roster, so that a robot side that verifies (masa_sim_robot --roster) takes commands from its key
// alone; the robot's state still arrives unsigned from the robot's SDK bridge, which a signed
// Transport would refuse. The bytes on the wire are those a signed Transport sends (SIG1 trailer,
// message_sign.hpp).
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "common/transport/message_sign.hpp"
#include "common/transport/transport.hpp"

namespace masa::transport {

class SignedPublisher {
 public:
  // Without a signer it publishes as `lcm` does (unsigned).
  SignedPublisher(Transport& lcm, std::shared_ptr<MessageSigner> signer);

  template <class Msg>
  bool publish(const std::string& channel, const Msg& msg) {
    if (!signer_) return lcm_.publish(channel, msg);
    std::lock_guard<std::mutex> lock(mutex_);
    const int size = msg.getEncodedSize();
    buf_.resize(static_cast<std::size_t>(size) + kSigTrailerBytes);
    if (msg.encode(buf_.data(), 0, size) != size) return false;
    return sealAndSend(channel, size);
  }
  bool signs() const { return signer_ != nullptr; }
  const MessageSigner* signer() const { return signer_.get(); }

 private:
  bool sealAndSend(const std::string& channel, int size);
  Transport& lcm_;
  std::shared_ptr<MessageSigner> signer_;
  std::mutex mutex_;
  std::vector<uint8_t> buf_;
};

// The size of the message in `data` without a SIG1 trailer, when it ends in one (unverified): for
// a receiver that does not verify and decodes strictly (decodeChecked), so that a signing sender's
// messages still decode. `size` when there is none.
int sizeWithoutSigTrailer(const void* data, int size);

}  // namespace masa::transport
