// The one layout of rollout data, from the actor that steps the environments to the PPO update.
//
// E environments stepped together for T steps, step-major: sample (t, e) is index t * E + e of
// every per-step array, and its vector occupies [(t * E + e) * dim, (t * E + e + 1) * dim). This is
// the order an actor writes (all environments advance one step together), the order of the wire
// chunk (lcmt_rollout_chunk, the same layout over a run of whole environments), the order of the
// learner's intake pool, and the memory of rollout::RolloutBuffer's matrices (column t * E + e), which
// are views over a Rollout. So the data is copied between these stages, never re-arranged.
//
// Truncations (time-outs) have one encoding everywhere: the step index t * E + e, ascending, and
// the observation the environment reached before its reset, for the value bootstrap.
//
// Allocated once per (E, T, dims); refilled every rollout without allocating.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace masa::rollout {

struct Rollout {
  int num_envs = 0;
  int horizon = 0;
  int obs_dim = 0;
  int act_dim = 0;

  std::vector<float> obs;           // (T+1) x E x obs_dim; row T is the bootstrap observation
  std::vector<float> actions;       // T x E x act_dim, sampled by the behaviour policy
  std::vector<float> mean;          // T x E x act_dim, behaviour mean
  std::vector<float> log_prob;      // T x E, behaviour log-probability (nats)
  std::vector<float> reward;        // T x E
  std::vector<uint8_t> terminated;  // T x E, 0/1
  std::vector<uint8_t> truncated;   // T x E, 0/1; each 1 has a final_obs entry
  // E x act_dim: the behaviour policy's (state-independent) log std of each environment. One
  // actor's environments share it; a learner batch can mix policy versions (max_policy_lag > 0).
  std::vector<float> env_log_std;

  // Truncated steps: final_index = t * E + e, ascending; final_obs holds their pre-reset
  // observations, obs_dim floats each. Capacity T*E is reserved so adding never allocates.
  std::vector<int32_t> final_index;
  std::vector<float> final_obs;

  // Episodes finished during the rollout (capacity T*E reserved).
  std::vector<int32_t> episode_env;      // environment index in [0, E)
  std::vector<float> episode_return;     // undiscounted
  std::vector<int32_t> episode_length;   // steps
  std::vector<int8_t> episode_success;   // 1, 0, or -1 (no success measure)
  std::vector<std::string> term_names;   // reward term names, fixed per task
  std::vector<float> episode_term_sums;  // num_episodes x num_terms

  // Sizes every array (zero-filled) and reserves the event lists; a no-op when the shape and
  // term names are unchanged, so calling it every rollout costs nothing.
  void allocate(int num_envs, int horizon, int obs_dim, int act_dim,
                const std::vector<std::string>& term_names = {});
  // Forgets the truncations and episodes of the previous rollout (keeps capacity).
  void clearEvents();

  // Records a truncated step (must come in ascending t * E + e order, as an actor steps).
  void addFinal(int t, int e, const float* pre_reset_obs);
  // Records a finished episode; term_sums has numTerms() floats (may be null when 0 terms).
  void addEpisode(int e, float ret, int length, int8_t success, const float* term_sums);
  // Sets every environment's behaviour log std to the same act_dim values.
  void setLogStd(const float* log_std);

  int numFinal() const { return static_cast<int>(final_index.size()); }
  int numEpisodes() const { return static_cast<int>(episode_env.size()); }
  int numTerms() const { return static_cast<int>(term_names.size()); }
  int numSteps() const { return num_envs * horizon; }

  // Offsets of (t, e) into the per-step arrays.
  std::size_t step(int t, int e) const { return static_cast<std::size_t>(t) * num_envs + e; }
  float* obsAt(int t, int e) { return obs.data() + step(t, e) * obs_dim; }
  const float* obsAt(int t, int e) const { return obs.data() + step(t, e) * obs_dim; }
  float* actionAt(int t, int e) { return actions.data() + step(t, e) * act_dim; }
  const float* actionAt(int t, int e) const { return actions.data() + step(t, e) * act_dim; }
  float* meanAt(int t, int e) { return mean.data() + step(t, e) * act_dim; }
  const float* meanAt(int t, int e) const { return mean.data() + step(t, e) * act_dim; }
  float* logStdOf(int e) { return env_log_std.data() + static_cast<std::size_t>(e) * act_dim; }
  const float* logStdOf(int e) const { return env_log_std.data() + static_cast<std::size_t>(e) * act_dim; }
  const float* finalObs(int i) const { return final_obs.data() + static_cast<std::size_t>(i) * obs_dim; }
};

}  // namespace masa::rollout
