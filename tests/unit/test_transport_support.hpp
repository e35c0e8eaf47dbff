// Shared helpers of the transport tests: random rollouts with truncations and episodes, and
// encoding a message to bytes as it would travel.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "common/rollout/rollout.hpp"
#include "learner/intake/batch_collector.hpp"
#include "common/rollout/rollout_buffer.hpp"
#include "masa/lcmt_policy_params.hpp"

namespace masa::transport::testing {

struct RolloutShape {
  int num_envs, horizon, obs_dim, act_dim;
};
inline constexpr RolloutShape kHumanoid{8, 32, 74, 21};
inline constexpr RolloutShape kTrifinger{20, 16, 41, 9};

// Random contents everywhere; about `event_prob` of the steps end an episode (half by the time
// limit, with a final observation), each finished episode with two reward terms.
inline void fillRandomRollout(rollout::Rollout& r, const RolloutShape& s, uint64_t seed, double event_prob = 0.05) {
  r.allocate(s.num_envs, s.horizon, s.obs_dim, s.act_dim, {"forward_velocity", "alive"});
  r.clearEvents();
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> normal;
  std::uniform_real_distribution<double> uniform;
  for (float& x : r.obs) x = normal(rng);
  for (float& x : r.actions) x = normal(rng);
  for (float& x : r.mean) x = normal(rng);
  for (float& x : r.log_prob) x = normal(rng);
  for (float& x : r.reward) x = normal(rng);
  std::vector<float> log_std(s.act_dim);  // one policy: every environment acts with it
  for (float& x : log_std) x = normal(rng);
  r.setLogStd(log_std.data());
  std::vector<float> final_obs(s.obs_dim);
  for (int t = 0; t < s.horizon; ++t) {
    for (int e = 0; e < s.num_envs; ++e) {
      const std::size_t i = r.step(t, e);
      r.terminated[i] = 0;
      r.truncated[i] = 0;
      if (uniform(rng) >= event_prob) continue;
      if (uniform(rng) < 0.5) {
        r.truncated[i] = 1;
        for (float& x : final_obs) x = normal(rng);
        r.addFinal(t, e, final_obs.data());
      } else {
        r.terminated[i] = 1;
      }
      const float terms[2] = {normal(rng), normal(rng)};
      const int8_t success = static_cast<int8_t>(static_cast<int>(uniform(rng) * 3) - 1);
      r.addEpisode(e, normal(rng), 1 + static_cast<int>(uniform(rng) * 500), success, terms);
    }
  }
}

// A batch as the learner takes it from its collector: the PPO buffer filled in place, and where
// each of its columns came from.
struct TakenBatch {
  explicit TakenBatch(const learner::CollectorConfig& c) : buffer(c.num_envs, c.horizon, c.obs_dim, c.act_dim) {}
  rollout::RolloutBuffer buffer;
  learner::BatchOrigin origin;
  const rollout::Rollout& data() const { return buffer.data(); }
};
inline bool take(learner::BatchCollector& collector, TakenBatch& batch) {
  return collector.take(batch.buffer, &batch.origin);
}

// A small, valid parameter broadcast: 40 parameters and a 6-dimensional normalizer.
inline masa::lcmt_policy_params samplePolicy() {
  masa::lcmt_policy_params p{};
  p.run_id = 42;
  p.utime = 1'700'000'000'000'000;
  p.version = 17;
  p.method = "masa";
  p.task = "a1_beam";
  p.num_params = 40;
  for (int i = 0; i < p.num_params; ++i) p.params.push_back(0.01f * static_cast<float>(i) - 0.2f);
  p.obs_dim = 6;
  p.obs_mean.assign(6, 0.5f);
  p.obs_std.assign(6, 2.0f);
  return p;
}

template <class Msg>
std::vector<uint8_t> encode(const Msg& m) {
  std::vector<uint8_t> buf(m.getEncodedSize());
  m.encode(buf.data(), 0, static_cast<int>(buf.size()));
  return buf;
}

}  // namespace masa::transport::testing
