#include "learner/offline/offline_config.hpp"

#include "common/core/config_error.hpp"

namespace masa::offline {
namespace {

// Typed reads of offline.<key> whose errors name the file (or "command line") that set the key.
class SectionReader {
 public:
  explicit SectionReader(const config::RunConfig& rc) : rc_(rc), node_(rc.resolved["offline"]) {}

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
  double openUnit(const std::string& key) const {
    const double v = get<double>(key, "a number");
    if (!(v > 0 && v < 1)) fail(key, "must be in (0, 1), got " + std::to_string(v));
    return v;
  }
  long long atLeast(const std::string& key, long long lo) const {
    const long long v = get<long long>(key, "an integer");
    if (v < lo) fail(key, "must be at least " + std::to_string(lo) + ", got " + std::to_string(v));
    return v;
  }
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    const std::string path = "offline." + key;
    const auto it = rc_.origin.find(path);
    throw ConfigError(it == rc_.origin.end() ? "configs/defaults.yaml" : it->second, path, what);
  }

 private:
  const config::RunConfig& rc_;
  YAML::Node node_;
};

}  // namespace

std::string algoName(Algo algo) { return algo == Algo::kBc ? "bc" : "iql"; }

OfflineConfig readOfflineConfig(const config::RunConfig& rc) {
  const SectionReader r(rc);
  OfflineConfig c;
  const std::string algo = r.get<std::string>("algo", "bc or iql");
  if (algo == "bc") c.algo = Algo::kBc;
  else if (algo == "iql") c.algo = Algo::kIql;
  else r.fail("algo", "expected bc or iql, got '" + algo + "'");
  c.augment = r.get<bool>("augment", "true or false");
  if (c.augment && rc.method != model::Method::kSa)
    r.fail("augment", "SASA-data trains the single-agent model on the augmented data: it needs method sa, not " +
                          model::methodName(rc.method));
  if (rc.method != model::Method::kSa && rc.method != model::Method::kMasa)
    throw ConfigError(rc.origin.count("method") ? rc.origin.at("method") : "configs/defaults.yaml", "method",
                      "offline learning runs sa, sasa-data (sa on augmented data) or masa, not " +
                          model::methodName(rc.method));
  c.steps = r.atLeast("steps", 1);
  c.batch_size = static_cast<int>(r.atLeast("batch_size", 1));
  c.learning_rate = r.positive("learning_rate");
  const std::string loss = r.get<std::string>("bc_loss", "gaussian or mse");
  if (loss == "gaussian") c.bc_loss = BcLoss::kGaussian;
  else if (loss == "mse") c.bc_loss = BcLoss::kMse;
  else r.fail("bc_loss", "expected gaussian or mse, got '" + loss + "'");
  c.expectile = r.openUnit("expectile");
  c.beta = r.positive("beta");
  c.max_weight = r.positive("max_weight");
  c.discount = r.get<double>("discount", "a number");
  if (!(c.discount >= 0 && c.discount <= 1)) r.fail("discount", "must be in [0, 1]");
  c.polyak = r.get<double>("polyak", "a number");
  if (!(c.polyak > 0 && c.polyak <= 1)) r.fail("polyak", "must be in (0, 1]");
  c.q_hidden = r.get<std::vector<int>>("q_hidden", "a list of integers");
  if (c.q_hidden.empty()) r.fail("q_hidden", "needs at least one layer width");
  for (int w : c.q_hidden)
    if (w < 1) r.fail("q_hidden", "layer widths must be positive");
  c.log_std_min = r.get<double>("log_std_min", "a number");
  c.log_std_max = r.get<double>("log_std_max", "a number");
  if (!(c.log_std_min < c.log_std_max)) r.fail("log_std_min", "must be below offline.log_std_max");
  c.normalize_reward = r.get<bool>("normalize_reward", "true or false");
  c.log_every = static_cast<int>(r.atLeast("log_every", 1));
  c.eval_every = r.atLeast("eval_every", 0);
  c.eval_episodes = static_cast<int>(r.atLeast("eval_episodes", 1));
  c.final_eval_episodes = static_cast<int>(r.atLeast("final_eval_episodes", 0));
  return c;
}

}  // namespace masa::offline
