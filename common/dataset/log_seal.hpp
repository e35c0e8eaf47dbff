// Seals in a dataset log: how an LCM log that masa writes proves its episodes intact while staying
// a plain LCM log for lcm-logplayer and lcm-spy. The writer puts a seal event (channel
// MASA_DATASET_SEAL) at the start of the log and after each episode; a seal holds the SHA-256 of
// every event since the seal before it, chained through that seal's digest:
//   digest_k = SHA-256("masa dataset log seal 1\n" | digest_{k-1} | u64 count |
//                      per event: u32 channel length, channel, u32 data length, data)
// with digest_0 all zeros; the seal's 48 bytes: "MASALSL1" | u64 count | digest_k (little-endian).
// An episode is recorded, flushed and sealed before the next begins, so a recorder killed mid-write
// leaves sealed episodes and an unsealed tail, which the reader refuses.
//
// The reader hands an event to the dataset only once the seal after it checks. A log with no seal
// at all (lcm-logger's recording of `masa_dataset record --publish`, or a log written before the
// seals) is read with a warning: its events are vetted one by one but nothing proves them intact.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "common/integrity/sha256.hpp"

namespace masa::dataset {

class LogSealChain {
 public:
  static constexpr std::size_t kSealBytes = 48;

  // An event (other than a seal) since the last seal.
  void add(std::string_view channel, std::string_view data);
  // The seal of the events added since the last one; the next segment chains on it.
  std::string seal();
  // Whether `seal_data` seals the events added since the last seal. The next segment chains on the
  // digest the seal holds, so that a damaged segment costs only itself.
  bool verify(std::string_view seal_data);
  int64_t pendingEvents() const { return count_; }

 private:
  integrity::Digest digestOfPending() const;

  integrity::Digest previous_{};
  std::string pending_;  // the events since the last seal, as they are hashed
  int64_t count_ = 0;
};

// Whether an event is a seal (or what is left of one): its channel, or its data's magic. Either is
// enough, so that a seal with a damaged channel name still counts as a seal that fails.
bool isSealEvent(std::string_view channel, std::string_view data);

}  // namespace masa::dataset
