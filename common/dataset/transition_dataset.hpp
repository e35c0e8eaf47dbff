// An offline dataset in memory: transitions (o, a, r, o', terminal, timeout) stored column-major
// like every batch in masa (features x N), with the episodes they came from.
//
// terminal: the episode ended by the task's termination (no bootstrap from o').
// timeout:  the episode was cut by the time limit at this step (bootstrap from o' is right, but
//           o' starts no further transition).
// Transitions of one episode are contiguous and in time order.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/core/types.hpp"

namespace masa::dataset {

struct EpisodeInfo {
  int64_t episode_id = 0;  // unique within the dataset's source (recorder run id, episode seed)
  int32_t policy_id = 0;   // which recording policy produced it (index into policy_names)
  int64_t start = 0;       // first transition's column
  int32_t length = 0;      // number of transitions
  double ret = 0;          // sum of its rewards
  int8_t success = -1;     // 1/0 at the episode's end, -1 where the task has no success notion
};

struct TransitionDataset {
  std::string task;                       // the task it was recorded in (e.g. "a1_beam")
  int obs_dim = 0, act_dim = 0;
  Mat<float> obs, next_obs;               // obs_dim x N
  Mat<float> actions;                     // act_dim x N
  Vec<float> rewards;                     // N
  std::vector<uint8_t> terminals;         // N
  std::vector<uint8_t> timeouts;          // N
  std::vector<EpisodeInfo> episodes;
  std::vector<std::string> policy_names;  // policy_id -> where it came from (file, stage)

  int64_t size() const { return rewards.size(); }

  // Throws std::runtime_error when the parts disagree (sizes, episodes not tiling the columns,
  // non-finite numbers).
  void validate() const;
};

}  // namespace masa::dataset
