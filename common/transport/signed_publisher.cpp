#include "common/transport/signed_publisher.hpp"

namespace masa::transport {

SignedPublisher::SignedPublisher(Transport& lcm, std::shared_ptr<MessageSigner> signer)
    : lcm_(lcm), signer_(std::move(signer)) {}

bool SignedPublisher::sealAndSend(const std::string& channel, int size) {
  signer_->seal(channel, buf_.data(), size, buf_.data() + size);
  return lcm_.publishWire(channel, buf_.data(), size + kSigTrailerBytes);
}

int sizeWithoutSigTrailer(const void* data, int size) {
  SenderId sender;
  uint64_t counter = 0;
  return peekSigner(data, size, sender, counter) ? size - kSigTrailerBytes : size;
}

}  // namespace masa::transport
