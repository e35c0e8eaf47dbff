// LCM channel names of masa. One set per network: messages of another run on the same channels
// are told apart by run_id and dropped.
#pragma once

namespace masa::transport {

inline constexpr const char* kRolloutChannel = "MASA_ROLLOUT";           // lcmt_rollout_chunk
inline constexpr const char* kPolicyChannel = "MASA_POLICY";             // lcmt_policy_params
inline constexpr const char* kLearnerStatsChannel = "MASA_LEARNER_STATS";  // lcmt_learner_stats
inline constexpr const char* kHeartbeatChannel = "MASA_ACTOR_HEARTBEAT";   // lcmt_actor_heartbeat
// A robot and its policy runner (masa_deploy, masa_sim_robot); the deploy config may rename them.
inline constexpr const char* kRobotStateChannel = "MASA_ROBOT_STATE";      // lcmt_robot_state
inline constexpr const char* kRobotCommandChannel = "MASA_ROBOT_COMMAND";  // lcmt_robot_command
// Offline datasets: recorded episodes (masa_dataset record).
inline constexpr const char* kDatasetChannel = "MASA_DATASET";            // lcmt_transitions
// A dataset log's seals (common/dataset/log_seal.hpp): 48 raw bytes, not an LCM type; only in files.
inline constexpr const char* kDatasetSealChannel = "MASA_DATASET_SEAL";

}  // namespace masa::transport
