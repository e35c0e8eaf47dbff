#include "learner/offline/offline_config.hpp"

#include <string>

namespace masa::offline {

std::string algoName(Algo algo) { return algo == Algo::kBc ? "bc" : "iql"; }

OfflineConfig readOfflineConfig(const config::RunConfig& rc) {
  const config::ConfigSection r = config::sectionOf(rc, "offline");
  OfflineConfig c;
  c.algo = r.oneOf("algo", {"bc", "iql"}) == "bc" ? Algo::kBc : Algo::kIql;
  c.augment = r.get<bool>("augment", "true or false");
  if (c.augment && rc.method != model::Method::kSa)
    r.fail("augment", "SASA-data trains the single-agent model on the augmented data: it needs method sa, not " +
                          model::methodName(rc.method));
  if (rc.method != model::Method::kSa && rc.method != model::Method::kMasa)
    config::sectionOf(rc, "").fail("method", "offline learning runs sa, sasa-data (sa on augmented data) or masa, not " +
                                                 model::methodName(rc.method));
  c.steps = r.atLeast("steps", 1LL);
  c.batch_size = r.atLeast("batch_size", 1);
  c.learning_rate = r.positive("learning_rate");
  c.bc_loss = r.oneOf("bc_loss", {"gaussian", "mse"}) == "gaussian" ? BcLoss::kGaussian : BcLoss::kMse;
  c.expectile = r.inRange("expectile", 0.0, 1.0, true, true);
  c.beta = r.positive("beta");
  c.max_weight = r.positive("max_weight");
  c.discount = r.inRange("discount", 0.0, 1.0);
  c.polyak = r.inRange("polyak", 0.0, 1.0, true);
  c.q_hidden = r.widths("q_hidden");
  c.log_std_min = r.number("log_std_min");
  c.log_std_max = r.number("log_std_max");
  if (!(c.log_std_min < c.log_std_max)) r.fail("log_std_min", "must be below offline.log_std_max");
  c.normalize_reward = r.get<bool>("normalize_reward", "true or false");
  c.log_every = r.atLeast("log_every", 1);
  c.eval_every = r.atLeast("eval_every", 0LL);
  c.eval_episodes = r.atLeast("eval_episodes", 1);
  c.final_eval_episodes = r.atLeast("final_eval_episodes", 0);
  return c;
}

}  // namespace masa::offline
