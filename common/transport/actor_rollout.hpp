// One actor rollout: E environments stepped together for T steps, in the layout of
// lcmt_rollout_chunk (step-major: index (t * num_envs + e) * dim + k) but for all of the actor's
// environments. Allocated once per (E, T, dims); the actor refills it every rollout, and the
// learner's batches reuse the same struct, so both sides share one set of index helpers.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace masa::transport {

struct ActorRollout {
  int num_envs = 0;
  int horizon = 0;
  int obs_dim = 0;
  int act_dim = 0;

  std::vector<float> obs;          // (T+1) x E x obs_dim; row T is the bootstrap observation
  std::vector<float> actions;      // T x E x act_dim, sampled by the behaviour policy
  std::vector<float> mean;         // T x E x act_dim, behaviour mean
  std::vector<float> log_prob;     // T x E, behaviour log-probability (nats)
  std::vector<float> reward;       // T x E
  std::vector<int8_t> terminated;  // T x E, 0/1
  std::vector<int8_t> truncated;   // T x E, 0/1; each 1 has a final_obs entry
  std::vector<float> log_std;      // act_dim

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
  // Records a finished episode; term_sums has num_terms() floats (may be null when 0 terms).
  void addEpisode(int e, float ret, int length, int8_t success, const float* term_sums);

  int numFinal() const { return static_cast<int>(final_index.size()); }
  int numEpisodes() const { return static_cast<int>(episode_env.size()); }
  int numTerms() const { return static_cast<int>(term_names.size()); }

  // Offsets of (t, e) into the per-step arrays.
  std::size_t step(int t, int e) const { return static_cast<std::size_t>(t) * num_envs + e; }
  float* obsAt(int t, int e) { return obs.data() + step(t, e) * obs_dim; }
  const float* obsAt(int t, int e) const { return obs.data() + step(t, e) * obs_dim; }
  float* actionAt(int t, int e) { return actions.data() + step(t, e) * act_dim; }
  const float* actionAt(int t, int e) const { return actions.data() + step(t, e) * act_dim; }
  float* meanAt(int t, int e) { return mean.data() + step(t, e) * act_dim; }
  const float* meanAt(int t, int e) const { return mean.data() + step(t, e) * act_dim; }
};

}  // namespace masa::transport
