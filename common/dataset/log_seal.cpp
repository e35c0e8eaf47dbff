#include "common/dataset/log_seal.hpp"

#include <cstring>

#include "common/transport/channels.hpp"

namespace masa::dataset {
namespace {

constexpr std::string_view kSealMagic = "MASALSL1";
constexpr std::string_view kContext = "masa dataset log seal 1\n";

template <class T>
void appendPod(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

}  // namespace

void LogSealChain::add(std::string_view channel, std::string_view data) {
  appendPod(pending_, static_cast<uint32_t>(channel.size()));
  pending_.append(channel);
  appendPod(pending_, static_cast<uint32_t>(data.size()));
  pending_.append(data);
  ++count_;
}

integrity::Digest LogSealChain::digestOfPending() const {
  integrity::Sha256 h;
  h.update(kContext).update(previous_.data(), previous_.size()).update(&count_, sizeof count_).update(pending_);
  return h.finish();
}

std::string LogSealChain::seal() {
  const integrity::Digest d = digestOfPending();
  std::string out(kSealMagic);
  appendPod(out, count_);
  out.append(reinterpret_cast<const char*>(d.data()), d.size());
  previous_ = d;
  pending_.clear();
  count_ = 0;
  return out;
}

bool LogSealChain::verify(std::string_view seal_data) {
  integrity::Digest stored{};
  int64_t count = -1;
  if (seal_data.size() == kSealBytes) {
    std::memcpy(&count, seal_data.data() + 8, sizeof count);
    std::memcpy(stored.data(), seal_data.data() + 16, stored.size());
  }
  const bool ok = seal_data.substr(0, kSealMagic.size()) == kSealMagic && count == count_ && digestOfPending() == stored;
  previous_ = stored;
  pending_.clear();
  count_ = 0;
  return ok;
}

bool isSealEvent(std::string_view channel, std::string_view data) {
  return channel == transport::kDatasetSealChannel || data.substr(0, kSealMagic.size()) == kSealMagic;
}

}  // namespace masa::dataset
