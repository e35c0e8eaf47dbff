// Records a policy's episodes in its task as a dataset: the evaluator's batched, seeded episodes
// (episode k resets from seed + k), each handed over whole when it ends.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "common/dataset/episode_record.hpp"
#include "common/model/actor_critic.hpp"
#include "common/sim/policy_evaluator.hpp"

namespace masa::dataset {

struct RecordOptions {
  task::EvalOptions eval;   // episodes, seed, deterministic (default here: sample), max_steps, threads
  std::string policy_name;  // recorded with each episode; its hash makes the episode ids unique
  RecordOptions() { eval.deterministic = false; }
};

// episode_id = (32-bit hash of the policy name) << 32 | (reset seed, low 32 bits): the same
// policy and seed name the same episode, so a log read twice is not counted twice.
int64_t episodeId(const std::string& policy_name, uint64_t seed);

// Runs the episodes; `sink` receives each one as it ends (in order of ending). Returns the
// evaluator's summary of the same episodes.
task::EvalSummary recordEpisodes(const task::TaskFactory& factory, model::ActorCritic<float>& model,
                                 const RecordOptions& options, const std::function<void(const EpisodeRecord&)>& sink);

}  // namespace masa::dataset
