// One recorded episode as the recorder holds it, before it becomes lcmt_transitions messages, and
// the conversion both ways: episodeMessages() splits it (long episodes into several messages, so
// that a published one stays a manageable size), checkTransitions() vets a received message
// before anything of it is used.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "masa/lcmt_transitions.hpp"

namespace masa::dataset {

struct EpisodeRecord {
  std::string task;
  int64_t episode_id = 0;
  int32_t policy_id = 0;
  std::string policy_name;
  Mat<float> obs;      // obs_dim x (T + 1): o_0 ... o_T (o_T: the next observation of the last step)
  Mat<float> actions;  // act_dim x T
  std::vector<float> rewards;  // T
  bool terminated = false, truncated = false;
  int8_t success = -1;

  int length() const { return static_cast<int>(rewards.size()); }
};

// The messages of one episode, each with at most max_steps transitions, in order.
std::vector<masa::lcmt_transitions> episodeMessages(const EpisodeRecord& e, int max_steps, int64_t utime);

// Empty when the message is self-consistent (lengths, dimensions, finite numbers, flags), else
// why not. Dimensions above these bounds are refused: no task of masa comes near them.
inline constexpr int kMaxDatasetDim = 1 << 16;
std::string checkTransitions(const masa::lcmt_transitions& m);

}  // namespace masa::dataset
