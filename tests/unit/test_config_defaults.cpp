// A default is stated in the defaults file (configs/defaults.yaml, configs/deploy/defaults.yaml: the
// schema, the one place a user reads and changes them) and mirrored in the structs' member
// initializers, which code that builds a config by hand uses. Every config (run, sac, offline,
// deploy) is held to its file here: reading the defaults file alone gives the struct's defaults.
#include <gtest/gtest.h>

#include <string>

#include <yaml-cpp/yaml.h>

#include "deploy/runner/deploy_config.hpp"
#include "learner/offline/offline_config.hpp"
#include "common/config/sac_config.hpp"

namespace masa {
namespace {

#define EXPECT_SAME(field) EXPECT_EQ(read.field, fresh.field) << #field

// The run config (ppo, runner, model, method, seed, learner) from the defaults file alone: the
// middle layer is a tree that names only the task, so no task file sets a key.
TEST(ConfigDefaults, TheRunStructIsTheDefaultsFile) {
  const config::RunConfig read = config::loadRunConfigOver(std::string(MASA_SOURCE_DIR) + "/configs", {},
                                                           YAML::Load("task: a1_beam"), "the test"),
                          fresh;
  EXPECT_SAME(method); EXPECT_SAME(seed); EXPECT_SAME(learner);
  EXPECT_SAME(rollout.num_envs); EXPECT_SAME(rollout.horizon); EXPECT_SAME(rollout.section); EXPECT_SAME(ppo.minibatch_size); EXPECT_SAME(ppo.mini_epochs);
  EXPECT_SAME(ppo.learning_rate); EXPECT_SAME(ppo.lr_schedule); EXPECT_SAME(ppo.kl_threshold); EXPECT_SAME(ppo.lr_min);
  EXPECT_SAME(ppo.lr_max); EXPECT_SAME(ppo.gamma); EXPECT_SAME(ppo.tau); EXPECT_SAME(ppo.e_clip);
  EXPECT_SAME(ppo.entropy_coef); EXPECT_SAME(ppo.critic_coef); EXPECT_SAME(ppo.bounds_loss_coef);
  EXPECT_SAME(ppo.soft_bound); EXPECT_SAME(ppo.grad_norm); EXPECT_SAME(ppo.normalize_value);
  EXPECT_SAME(ppo.normalize_advantage); EXPECT_SAME(ppo.value_bootstrap); EXPECT_SAME(rollout.max_updates);
  EXPECT_SAME(rollout.max_policy_lag);
  EXPECT_SAME(runner.checkpoint_every); EXPECT_SAME(runner.republish_every_s); EXPECT_SAME(runner.plot_every);
  EXPECT_SAME(runner.eval_every); EXPECT_SAME(runner.eval_episodes); EXPECT_SAME(runner.silence_warn_s);
  EXPECT_SAME(runner.rank_silence_stop_s); EXPECT_SAME(runner.snapshot_every); EXPECT_SAME(runner.min_batch_fraction);
  EXPECT_SAME(runner.loss_grace_s); EXPECT_SAME(runner.repeat_unacknowledged_s);
  EXPECT_SAME(model.method); EXPECT_SAME(model.policy_hidden); EXPECT_SAME(model.critic_hidden);
  EXPECT_SAME(model.critic_head_hidden); EXPECT_SAME(model.activation); EXPECT_SAME(model.init_log_std);
  EXPECT_SAME(model.policy_last_layer_scale); EXPECT_SAME(model.sasa_policy_coef); EXPECT_SAME(model.sasa_value_coef);
  EXPECT_SAME(model.normalize_obs);
}

// a1_beam's task file sets only ppo, runner, model and env keys, so sac and offline are the defaults'.
config::RunConfig defaultsRun() {
  return config::loadRunConfig(std::string(MASA_SOURCE_DIR) + "/configs", {"task=a1_beam"});
}

TEST(ConfigDefaults, TheSacStructIsTheDefaultsFile) {
  const sac::SacConfig read = sac::readSacConfig(defaultsRun()), fresh;
  EXPECT_SAME(env_steps); EXPECT_SAME(buffer_size); EXPECT_SAME(batch_size); EXPECT_SAME(learning_starts);
  EXPECT_SAME(updates_per_step); EXPECT_SAME(n_step); EXPECT_SAME(discount); EXPECT_SAME(polyak);
  EXPECT_SAME(policy_lr); EXPECT_SAME(q_lr); EXPECT_SAME(alpha_lr); EXPECT_SAME(init_alpha); EXPECT_SAME(autotune);
  EXPECT_SAME(target_entropy_per_dim); EXPECT_SAME(policy_hidden); EXPECT_SAME(q_hidden); EXPECT_SAME(log_std_min);
  EXPECT_SAME(log_std_max); EXPECT_SAME(log_every); EXPECT_SAME(eval_every); EXPECT_SAME(eval_episodes);
  EXPECT_SAME(checkpoint_every);
}

TEST(ConfigDefaults, TheOfflineStructIsTheDefaultsFile) {
  const offline::OfflineConfig read = offline::readOfflineConfig(defaultsRun()), fresh;
  EXPECT_SAME(algo); EXPECT_SAME(augment); EXPECT_SAME(steps); EXPECT_SAME(batch_size); EXPECT_SAME(learning_rate);
  EXPECT_SAME(bc_loss); EXPECT_SAME(expectile); EXPECT_SAME(beta); EXPECT_SAME(max_weight); EXPECT_SAME(discount);
  EXPECT_SAME(polyak); EXPECT_SAME(q_hidden); EXPECT_SAME(log_std_min); EXPECT_SAME(log_std_max);
  EXPECT_SAME(normalize_reward); EXPECT_SAME(log_every); EXPECT_SAME(eval_every); EXPECT_SAME(eval_episodes);
  EXPECT_SAME(final_eval_episodes);
}

TEST(ConfigDefaults, TheDeployStructIsTheDefaultsFile) {
  const deploy::DeployConfig read = deploy::loadDeployConfig(""), fresh;
  EXPECT_SAME(state_channel); EXPECT_SAME(command_channel); EXPECT_SAME(control_rate_hz); EXPECT_SAME(start_guard_s);
  EXPECT_SAME(calibration_max_rate); EXPECT_SAME(calibration_settle_s); EXPECT_SAME(stale_after_s);
  EXPECT_SAME(action_clip); EXPECT_SAME(position_margin); EXPECT_SAME(max_target_rate); EXPECT_SAME(max_kp);
  EXPECT_SAME(max_kd); EXPECT_SAME(safe_mode); EXPECT_SAME(damping_kd); EXPECT_SAME(hold_kp); EXPECT_SAME(hold_kd);
  EXPECT_SAME(max_roll); EXPECT_SAME(max_pitch); EXPECT_SAME(emergency_response); EXPECT_SAME(crouch_pose);
  EXPECT_SAME(crouch_max_rate); EXPECT_SAME(crouch_kp); EXPECT_SAME(crouch_kd); EXPECT_SAME(realtime.cpu);
  EXPECT_SAME(realtime.priority); EXPECT_SAME(realtime.lock_memory); EXPECT_SAME(busy_poll_us); EXPECT_SAME(warm_up_us);
}

#undef EXPECT_SAME

}  // namespace
}  // namespace masa
