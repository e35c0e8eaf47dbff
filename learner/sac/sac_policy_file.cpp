#include "learner/sac/sac_policy_file.hpp"

#include <sstream>
#include <stdexcept>

#include "common/policy/policy_file.hpp"

namespace masa::sac {

config::RunConfig policyFileConfig(const config::RunConfig& rc, const SacConfig& sc, bool normalizes) {
  config::RunConfig out = rc;
  out.resolved = YAML::Clone(rc.resolved);
  out.env = YAML::Clone(rc.env);
  YAML::Node m = out.resolved["model"];
  m["policy_hidden"] = sc.policy_hidden;
  m["critic_hidden"] = std::vector<int>{1};
  m["critic_head_hidden"] = YAML::Node(YAML::NodeType::Sequence);
  m["normalize_input"] = normalizes;
  out.model.policy_hidden = sc.policy_hidden;
  out.model.critic_hidden = {1};
  out.model.critic_head_hidden = {};
  out.model.normalize_obs = normalizes;
  for (const char* key : {"model.policy_hidden", "model.critic_hidden", "model.critic_head_hidden", "model.normalize_input"})
    out.origin[key] = "masa_sac's policy file";
  return out;
}

std::unique_ptr<model::ActorCritic<float>> toActorCritic(const SacPolicy<float>& policy, const sym::SymmetrySpec& spec,
                                                         model::ModelConfig model) {
  MASA_CHECK(model.method == policy.shape().method && model.policy_hidden == policy.shape().hidden &&
                 model.activation == policy.shape().activation,
             "the policy file's model config does not describe the SAC policy (method, hidden widths, activation)");
  model.squash = model::ActionSquash::kTanh;
  auto ac = std::make_unique<model::ActorCritic<float>>(spec, model);
  // Every parameter zero, then Phi's layers copied: "policy.layer<k>.*" from "sac_policy.layer<k>.*",
  // the last layer's first rows (the mean part of each agent's output).
  ac->params().values().setZero();
  const auto& src = policy.params();
  for (const auto& seg : ac->params().segments()) {
    if (seg.name.rfind("policy.layer", 0) != 0) continue;
    const nn::ParameterSegment& from = src.segment("sac_" + seg.name);
    MASA_CHECK(from.cols == seg.cols && from.rows >= seg.rows,
               "SAC segment " << from.name << " is " << from.rows << " x " << from.cols << ", the file's " << seg.name
                              << " " << seg.rows << " x " << seg.cols);
    ac->params().value(seg.offset, seg.rows, seg.cols) = src.value(from.offset, from.rows, from.cols).topRows(seg.rows);
  }
  std::stringstream norm(std::ios::in | std::ios::out | std::ios::binary);
  policy.obsNormalizer().save(norm);
  ac->obsNormalizer().load(norm);
  return ac;
}

void saveSacPolicyFile(const std::string& path, const config::RunConfig& rc, const SacConfig& sc,
                       const SacPolicy<float>& policy, const sym::SymmetrySpec& spec) {
  const config::RunConfig file_rc = policyFileConfig(rc, sc, policy.normalizes());
  const auto ac = toActorCritic(policy, spec, file_rc.model);
  policy::savePolicyFile(path, file_rc, *ac);
}

}  // namespace masa::sac
