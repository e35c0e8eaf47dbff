#include "common/transport/chunk_wire_guard.hpp"

#include <cstdint>

#include "masa/lcmt_rollout_chunk.hpp"

namespace masa::transport {

namespace {
class Reader {
 public:
  Reader(const uint8_t* p, int64_t size) : p_(p), size_(size) {}
  bool skip(int64_t bytes) {
    if (bytes < 0 || bytes > size_ - pos_) return ok_ = false;
    pos_ += bytes;
    return ok_;
  }
  // LCM encodes integers big-endian.
  bool count(int64_t& n) {
    if (!ok_ || size_ - pos_ < 4) return ok_ = false;
    const uint8_t* q = p_ + pos_;
    n = static_cast<int32_t>((uint32_t(q[0]) << 24) | (uint32_t(q[1]) << 16) | (uint32_t(q[2]) << 8) | uint32_t(q[3]));
    pos_ += 4;
    if (n < 0) return ok_ = false;
    return ok_;
  }
  bool fail() { return ok_ = false; }
  bool atEnd() const { return ok_ && pos_ == size_; }
  bool ok() const { return ok_; }

 private:
  const uint8_t* p_;
  int64_t size_, pos_ = 0;
  bool ok_ = true;
};
}  // namespace

bool chunkWireLengthsFit(const void* data, int size) {
  if (data == nullptr || size < 8) return false;
  const auto* p = static_cast<const uint8_t*>(data);
  int64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = (hash << 8) | p[i];
  if (hash != masa::lcmt_rollout_chunk::getHash()) return false;

  Reader r(p + 8, size - 8);
  int64_t n = 0;
  // run_id, actor_id, rollout_seq, chunk_index, num_chunks, policy_version, then horizon, obs_dim,
  // act_dim, num_envs, env_offset.
  r.skip(8 + 4 + 8 + 4 + 4 + 8 + 4 * 5);
  if (r.count(n)) r.skip(4 * n);          // obs
  if (r.count(n)) r.skip(2 * 4 * n);      // actions, mean
  if (r.count(n)) r.skip((4 + 4 + 1 + 1) * n);  // log_prob, reward, terminated, truncated
  if (r.count(n)) r.skip(4 * n);          // log_std
  if (r.count(n)) r.skip(4 * n);          // final_index
  if (r.count(n)) r.skip(4 * n);          // final_obs
  if (r.count(n)) r.skip((4 + 4 + 4 + 1) * n);  // episode_env, _return, _length, _success
  if (r.count(n)) {                       // term_names: each int32 length (with NUL), bytes
    for (int64_t i = 0; i < n && r.ok(); ++i) {
      int64_t len = 0;
      // A zero length would make the generated decoder assign SIZE_MAX characters.
      if (r.count(len)) len >= 1 ? r.skip(len) : r.fail();
    }
  }
  if (r.count(n)) r.skip(4 * n);          // episode_term_sums
  return r.atEnd();
}

}  // namespace masa::transport
