#include "deploy/runner/foreign_runners.hpp"

#include "common/transport/signed_publisher.hpp"

namespace masa::deploy {

void ForeignRunners::listen(transport::Transport& from, const std::string& channel,
                            const masa::lcmt_robot_command& sized, int64_t own_id) {
  scratch_ = sized;
  verified_ = from.authenticates();
  from.subscribeRaw(channel, [this, own_id](const void* data, int size) {
    // A verifying transport hands over the message without its trailer; unverified, a signing
    // runner's trailer is cut off unchecked (sizeWithoutSigTrailer).
    if (!verified_) size = transport::sizeWithoutSigTrailer(data, size);
    if (transport::decodeChecked(data, size, scratch_) != transport::WireVerdict::kOk) {
      ++undecodable_;
      return;
    }
    if (scratch_.runner_id == own_id) return;
    ++heard_;
    last_id_ = scratch_.runner_id;
  });
}

}  // namespace masa::deploy
