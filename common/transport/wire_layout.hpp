// The wire layout of every masa LCM type, as a table of fields in lcmtypes/*.lcm order: what the
// wire guard walks before lcm-gen's decoder is allowed to touch a message.
//
// lcm-gen's wire format: an 8-byte type hash, then each field in declaration order, big-endian;
// a string is an int32 length (bytes including the NUL), then those bytes; a variable array is
// its elements back to back, its length given by an earlier integer field. The tables name each
// field and its type exactly as the .lcm file does, so that a unit test recomputes lcm-gen's type
// hash from them: a field added, removed, renamed, retyped or reordered in a .lcm file without
// the same change here fails that test.
#pragma once

#include <span>
#include <string_view>

namespace masa {
class lcmt_rollout_chunk;
class lcmt_policy_params;
class lcmt_learner_stats;
class lcmt_actor_heartbeat;
class lcmt_robot_state;
class lcmt_robot_command;
class lcmt_transitions;
}  // namespace masa

namespace masa::transport {

// LCM's primitive types (the names are lcm-gen's, used by its hash).
enum class WireType { kInt8, kInt16, kInt32, kInt64, kFloat, kDouble, kByte, kBoolean, kString };

struct WireField {
  std::string_view name;
  WireType type;
  std::string_view length = {};  // empty: one value; else the earlier integer field with the array length
};

// WireLayoutOf<Msg>::fields: the fields of Msg in wire order.
template <class Msg>
struct WireLayoutOf;

template <>
struct WireLayoutOf<masa::lcmt_policy_params> {
  static constexpr WireField fields[] = {
      {"run_id", WireType::kInt64},        {"utime", WireType::kInt64},
      {"version", WireType::kInt64},       {"method", WireType::kString},
      {"task", WireType::kString},         {"num_params", WireType::kInt32},
      {"params", WireType::kFloat, "num_params"},
      {"obs_dim", WireType::kInt32},       {"obs_mean", WireType::kFloat, "obs_dim"},
      {"obs_std", WireType::kFloat, "obs_dim"},
  };
};

template <>
struct WireLayoutOf<masa::lcmt_actor_heartbeat> {
  static constexpr WireField fields[] = {
      {"run_id", WireType::kInt64},   {"actor_id", WireType::kInt32},        {"utime", WireType::kInt64},
      {"hostname", WireType::kString}, {"num_envs", WireType::kInt32},       {"steps_per_second", WireType::kFloat},
      {"policy_version", WireType::kInt64}, {"rollouts_sent", WireType::kInt64},
      {"params_version", WireType::kInt64},
  };
};

template <>
struct WireLayoutOf<masa::lcmt_learner_stats> {
  static constexpr WireField fields[] = {
      {"run_id", WireType::kInt64},
      {"utime", WireType::kInt64},
      {"update", WireType::kInt64},
      {"env_steps", WireType::kInt64},
      {"fps", WireType::kFloat},
      {"mean_episode_return", WireType::kFloat},
      {"mean_episode_length", WireType::kFloat},
      {"success_rate", WireType::kFloat},
      {"num_episodes", WireType::kInt32},
      {"actor_loss", WireType::kFloat},
      {"critic_loss", WireType::kFloat},
      {"entropy", WireType::kFloat},
      {"bounds_loss", WireType::kFloat},
      {"symmetry_policy_loss", WireType::kFloat},
      {"symmetry_value_loss", WireType::kFloat},
      {"kl", WireType::kFloat},
      {"learning_rate", WireType::kFloat},
      {"grad_norm", WireType::kFloat},
      {"explained_variance", WireType::kFloat},
      {"num_drop_reasons", WireType::kInt32},
      {"drop_reason_names", WireType::kString, "num_drop_reasons"},
      {"drop_counts", WireType::kInt64, "num_drop_reasons"},
      {"num_terms", WireType::kInt32},
      {"term_names", WireType::kString, "num_terms"},
      {"term_means", WireType::kFloat, "num_terms"},
  };
};

template <>
struct WireLayoutOf<masa::lcmt_rollout_chunk> {
  static constexpr WireField fields[] = {
      {"run_id", WireType::kInt64},
      {"actor_id", WireType::kInt32},
      {"incarnation", WireType::kInt64},
      {"rollout_seq", WireType::kInt64},
      {"chunk_index", WireType::kInt32},
      {"num_chunks", WireType::kInt32},
      {"policy_version", WireType::kInt64},
      {"horizon", WireType::kInt32},
      {"obs_dim", WireType::kInt32},
      {"act_dim", WireType::kInt32},
      {"num_envs", WireType::kInt32},
      {"env_offset", WireType::kInt32},
      {"obs_len", WireType::kInt32},
      {"obs", WireType::kFloat, "obs_len"},
      {"act_len", WireType::kInt32},
      {"actions", WireType::kFloat, "act_len"},
      {"mean", WireType::kFloat, "act_len"},
      {"step_len", WireType::kInt32},
      {"log_prob", WireType::kFloat, "step_len"},
      {"reward", WireType::kFloat, "step_len"},
      {"terminated", WireType::kInt8, "step_len"},
      {"truncated", WireType::kInt8, "step_len"},
      {"log_std_len", WireType::kInt32},
      {"log_std", WireType::kFloat, "log_std_len"},
      {"num_final", WireType::kInt32},
      {"final_index", WireType::kInt32, "num_final"},
      {"final_obs_len", WireType::kInt32},
      {"final_obs", WireType::kFloat, "final_obs_len"},
      {"num_episodes", WireType::kInt32},
      {"episode_env", WireType::kInt32, "num_episodes"},
      {"episode_return", WireType::kFloat, "num_episodes"},
      {"episode_length", WireType::kInt32, "num_episodes"},
      {"episode_success", WireType::kInt8, "num_episodes"},
      {"num_terms", WireType::kInt32},
      {"term_names", WireType::kString, "num_terms"},
      {"term_sums_len", WireType::kInt32},
      {"episode_term_sums", WireType::kFloat, "term_sums_len"},
  };
};

template <>
struct WireLayoutOf<masa::lcmt_robot_state> {
  static constexpr WireField fields[] = {
      {"utime", WireType::kInt64},
      {"num_joints", WireType::kInt32},
      {"joint_position", WireType::kDouble, "num_joints"},
      {"joint_velocity", WireType::kDouble, "num_joints"},
      {"joint_torque", WireType::kDouble, "num_joints"},
      {"has_base", WireType::kBoolean},
      {"base_x", WireType::kDouble},  {"base_y", WireType::kDouble},  {"base_z", WireType::kDouble},
      {"base_qw", WireType::kDouble}, {"base_qx", WireType::kDouble}, {"base_qy", WireType::kDouble},
      {"base_qz", WireType::kDouble},
      {"base_vx", WireType::kDouble}, {"base_vy", WireType::kDouble}, {"base_vz", WireType::kDouble},
      {"base_wx", WireType::kDouble}, {"base_wy", WireType::kDouble}, {"base_wz", WireType::kDouble},
  };
};

template <>
struct WireLayoutOf<masa::lcmt_robot_command> {
  static constexpr WireField fields[] = {
      {"utime", WireType::kInt64},
      {"state_utime", WireType::kInt64},
      {"runner_id", WireType::kInt64},
      {"sequence", WireType::kInt64},
      {"mode", WireType::kInt8},
      {"num_joints", WireType::kInt32},
      {"position", WireType::kDouble, "num_joints"},
      {"velocity", WireType::kDouble, "num_joints"},
      {"torque_ff", WireType::kDouble, "num_joints"},
      {"kp", WireType::kDouble, "num_joints"},
      {"kd", WireType::kDouble, "num_joints"},
  };
};

template <>
struct WireLayoutOf<masa::lcmt_transitions> {
  static constexpr WireField fields[] = {
      {"utime", WireType::kInt64},
      {"task", WireType::kString},
      {"episode_id", WireType::kInt64},
      {"policy_id", WireType::kInt32},
      {"policy_name", WireType::kString},
      {"step_offset", WireType::kInt32},
      {"num_steps", WireType::kInt32},
      {"obs_dim", WireType::kInt32},
      {"act_dim", WireType::kInt32},
      {"obs_len", WireType::kInt32},
      {"obs", WireType::kFloat, "obs_len"},
      {"actions_len", WireType::kInt32},
      {"actions", WireType::kFloat, "actions_len"},
      {"rewards", WireType::kFloat, "num_steps"},
      {"last", WireType::kBoolean},
      {"terminated", WireType::kBoolean},
      {"truncated", WireType::kBoolean},
      {"success", WireType::kInt8},
  };
};

}  // namespace masa::transport
