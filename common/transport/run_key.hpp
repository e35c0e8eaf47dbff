// A training run's secret: 32 random bytes under which every message of the run is authenticated
// (message_auth.hpp). On disk it is one line of 64 hex digits in a file of mode 0600, the run
// directory's run.key: made by deploy/run_key.sh (deploy/train.sh calls it before starting
// anything) or by the learner, carried by deploy/train.sh to the actor hosts, given to each
// process with --key-file. Never put a key on a command line: `ps` shows those to every user.
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace masa::transport {

struct RunKey {
  static constexpr int kBytes = 32;
  std::array<uint8_t, kBytes> bytes{};

  // From OpenSSL's random generator (seeded by the kernel); throws std::runtime_error if it fails.
  static RunKey random();
  // 8 hex digits of the key's SHA-256: learner and actors print it, so that a mismatch shows in
  // their logs without the key itself being shown.
  std::string id() const;
  bool operator==(const RunKey&) const = default;
};

// Reads a key file; throws std::runtime_error naming the file and what is wrong with it (missing,
// not 64 hex digits). Warns on stderr when others than the owner may read it.
RunKey readRunKey(const std::string& path);

// The key in `path`, made first (random, mode 0600) when there is none. Safe against a concurrent
// reader or maker: the file appears whole, and when two processes race, both get the winner's key.
RunKey readOrCreateRunKey(const std::string& path);

}  // namespace masa::transport
