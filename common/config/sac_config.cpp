#include "common/config/sac_config.hpp"

#include <cmath>
#include <string>

namespace masa::sac {

SacConfig readSacConfig(const config::RunConfig& rc) {
  const config::ConfigSection r = config::sectionOf(rc, "sac");
  SacConfig c;
  c.algorithm = r.oneOf("algorithm", {"sac", "td3"});
  c.env_steps = r.atLeast("env_steps", 1LL);
  c.buffer_size = r.atLeast("buffer_size", 1LL);
  c.batch_size = r.atLeast("batch_size", 1);
  c.learning_starts = r.atLeast("learning_starts", 1LL);
  c.updates_per_step = r.positive("updates_per_step");
  c.threads = r.atLeast("threads", 1);
  c.n_step = r.atLeast("n_step", 1);
  c.discount = r.inRange("discount", 0.0, 1.0);
  c.polyak = r.inRange("polyak", 0.0, 1.0, true);
  c.policy_lr = r.positive("policy_lr");
  c.q_lr = r.positive("q_lr");
  c.alpha_lr = r.positive("alpha_lr");
  c.init_alpha = r.positive("init_alpha");
  c.autotune = r.get<bool>("autotune", "true or false");
  c.target_entropy_per_dim = r.number("target_entropy_per_dim");
  c.policy_hidden = r.widths("policy_hidden");
  c.q_hidden = r.widths("q_hidden");
  c.log_std_min = r.number("log_std_min");
  c.log_std_max = r.number("log_std_max");
  if (!(c.log_std_min < c.log_std_max)) r.fail("log_std_min", "must be below sac.log_std_max");
  c.log_every = r.atLeast("log_every", 1LL);
  c.eval_every = r.atLeast("eval_every", 0LL);
  c.eval_episodes = r.atLeast("eval_episodes", 1);
  c.checkpoint_every = r.atLeast("checkpoint_every", 0LL);
  // A checkpoint is taken at a metrics row, where the row's sums are empty: nothing else to save.
  if (c.checkpoint_every % c.log_every != 0)
    r.fail("checkpoint_every", "must be a multiple of sac.log_every (" + std::to_string(c.log_every) + ")");
  c.td3_exploration_noise = r.nonNegative("td3_exploration_noise");
  c.td3_policy_noise = r.nonNegative("td3_policy_noise");
  c.td3_noise_clip = r.nonNegative("td3_noise_clip");
  c.td3_policy_delay = r.atLeast("td3_policy_delay", 1);
  c.her_share = r.inRange("her_share", 0.0, 1.0);
  c.her_future_window = r.atLeast("her_future_window", 0LL);
  c.checkpoint_replay = r.atLeast("checkpoint_replay", -1LL);
  return c;
}

SacPolicyShape policyShape(const config::RunConfig& rc, const SacConfig& sc) {
  SacPolicyShape s;
  s.method = rc.method;
  s.hidden = sc.policy_hidden;
  s.activation = rc.model.activation;
  s.log_std_min = sc.log_std_min;
  s.log_std_max = sc.log_std_max;
  s.sasa_coef = rc.model.sasa_policy_coef;
  return s;
}

long long gradientStepsOwed(const SacConfig& sc, long long steps_past_start) {
  if (steps_past_start <= 0) return 0;
  // + 1e-9: a ratio like 0.1 times 10 steps is one step, not 0.9999999.
  return static_cast<long long>(std::floor(sc.updates_per_step * static_cast<double>(steps_past_start) + 1e-9));
}

}  // namespace masa::sac
