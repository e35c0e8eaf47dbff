#include "learner/sac/sac_config.hpp"

#include "common/core/config_error.hpp"

namespace masa::sac {
namespace {

// Typed reads of sac.<key> whose errors name the file (or "command line") that set the key.
class SacSection {
 public:
  explicit SacSection(const config::RunConfig& rc) : rc_(rc), node_(rc.resolved["sac"]) {}

  template <typename T>
  T get(const std::string& key, const char* what) const {
    try {
      return node_[key].as<T>();
    } catch (const YAML::Exception&) {
      fail(key, std::string("expected ") + what);
    }
  }
  double positive(const std::string& key) const {
    const double v = get<double>(key, "a number");
    if (!(v > 0)) fail(key, "must be positive, got " + std::to_string(v));
    return v;
  }
  long long atLeast(const std::string& key, long long lo) const {
    const long long v = get<long long>(key, "an integer");
    if (v < lo) fail(key, "must be at least " + std::to_string(lo) + ", got " + std::to_string(v));
    return v;
  }
  std::vector<int> widths(const std::string& key) const {
    const auto w = get<std::vector<int>>(key, "a list of integers");
    if (w.empty()) fail(key, "needs at least one layer width");
    for (int x : w)
      if (x < 1) fail(key, "layer widths must be positive");
    return w;
  }
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    const std::string path = "sac." + key;
    const auto it = rc_.origin.find(path);
    throw ConfigError(it == rc_.origin.end() ? "configs/defaults.yaml" : it->second, path, what);
  }

 private:
  const config::RunConfig& rc_;
  YAML::Node node_;
};

}  // namespace

SacConfig readSacConfig(const config::RunConfig& rc) {
  const SacSection r(rc);
  SacConfig c;
  c.algorithm = r.get<std::string>("algorithm", "sac or td3");
  if (c.algorithm != "sac" && c.algorithm != "td3") r.fail("algorithm", "must be sac or td3, got '" + c.algorithm + "'");
  c.env_steps = r.atLeast("env_steps", 1);
  c.buffer_size = r.atLeast("buffer_size", 1);
  c.batch_size = static_cast<int>(r.atLeast("batch_size", 1));
  c.learning_starts = r.atLeast("learning_starts", 1);
  c.updates_per_step = static_cast<int>(r.atLeast("updates_per_step", 1));
  c.n_step = static_cast<int>(r.atLeast("n_step", 1));
  c.discount = r.get<double>("discount", "a number");
  if (!(c.discount >= 0 && c.discount <= 1)) r.fail("discount", "must be in [0, 1]");
  c.polyak = r.get<double>("polyak", "a number");
  if (!(c.polyak > 0 && c.polyak <= 1)) r.fail("polyak", "must be in (0, 1]");
  c.policy_lr = r.positive("policy_lr");
  c.q_lr = r.positive("q_lr");
  c.alpha_lr = r.positive("alpha_lr");
  c.init_alpha = r.positive("init_alpha");
  c.autotune = r.get<bool>("autotune", "true or false");
  c.target_entropy_per_dim = r.get<double>("target_entropy_per_dim", "a number");
  c.policy_hidden = r.widths("policy_hidden");
  c.q_hidden = r.widths("q_hidden");
  c.log_std_min = r.get<double>("log_std_min", "a number");
  c.log_std_max = r.get<double>("log_std_max", "a number");
  if (!(c.log_std_min < c.log_std_max)) r.fail("log_std_min", "must be below sac.log_std_max");
  c.log_every = r.atLeast("log_every", 1);
  c.eval_every = r.atLeast("eval_every", 0);
  c.eval_episodes = static_cast<int>(r.atLeast("eval_episodes", 1));
  c.checkpoint_every = r.atLeast("checkpoint_every", 0);
  // A checkpoint is taken at a metrics row, where the row's sums are empty: nothing else to save.
  if (c.checkpoint_every % c.log_every != 0)
    r.fail("checkpoint_every", "must be a multiple of sac.log_every (" + std::to_string(c.log_every) + ")");
  c.td3_exploration_noise = r.get<double>("td3_exploration_noise", "a number");
  if (!(c.td3_exploration_noise >= 0)) r.fail("td3_exploration_noise", "must not be negative");
  c.td3_policy_noise = r.get<double>("td3_policy_noise", "a number");
  if (!(c.td3_policy_noise >= 0)) r.fail("td3_policy_noise", "must not be negative");
  c.td3_noise_clip = r.get<double>("td3_noise_clip", "a number");
  if (!(c.td3_noise_clip >= 0)) r.fail("td3_noise_clip", "must not be negative");
  c.td3_policy_delay = static_cast<int>(r.atLeast("td3_policy_delay", 1));
  return c;
}

}  // namespace masa::sac
