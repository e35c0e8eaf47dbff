// masa_sac's policy as a common policy file (common/policy/policy_file.hpp): the file masa_eval,
// masa_export and masa_deploy read, format version 2 with the tanh squash, so that they act with
// SAC's deterministic action tanh(mean) exactly as masa_sac's own evaluation does.
//
// The SAC policy's shared network Phi outputs [mean part; log-std part] per agent (sac_policy.hpp);
// the file's ActorCritic has the same Phi with its last layer cut to the mean rows (the first
// agent_output_dim), the same agent maps, and the SAC policy's observation normalizer (applied
// only when the SAC policy applies it: model.normalize_input records which). What SAC has no
// counterpart for is a placeholder: the critic is zero (V = 0, width 1: SAC's twin Q(o, a) stays in
// sac_state.bin), the tied log-std is 0. The recorded configuration is the run's, with
// model.policy_hidden = sac.policy_hidden, model.critic_hidden = [1], model.critic_head_hidden = []
// and model.normalize_input as applied.
#pragma once

#include <memory>
#include <string>

#include "common/config/run_config.hpp"
#include "common/model/actor_critic.hpp"
#include "common/config/sac_config.hpp"
#include "common/model/sac_policy.hpp"

namespace masa::sac {

// The run configuration a SAC policy file records (rc's resolved tree is cloned, not changed).
config::RunConfig policyFileConfig(const config::RunConfig& rc, const SacConfig& sc, bool normalizes);

// An ActorCritic whose actMean is the SAC policy's tanh(mean); its config is `model`
// (policyFileConfig(...).model), with squash set to tanh here.
std::unique_ptr<model::ActorCritic<float>> toActorCritic(const SacPolicy<float>& policy, const sym::SymmetrySpec& spec,
                                                         model::ModelConfig model);

// Writes `policy` as a sealed policy file (atomically, signed when the seal's key is configured).
void saveSacPolicyFile(const std::string& path, const config::RunConfig& rc, const SacConfig& sc,
                       const SacPolicy<float>& policy, const sym::SymmetrySpec& spec);

}  // namespace masa::sac
