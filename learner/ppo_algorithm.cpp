#include "learner/ppo_algorithm.hpp"

#include <cmath>
#include <cstdio>
#include <istream>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "common/cluster/rank_agreement.hpp"
#include "common/core/binary_io.hpp"
#include "common/core/check.hpp"
#include "common/policy/policy_file.hpp"
#include "common/symmetry/symmetry_spec.hpp"
#include "learner/run_dir/checkpoint.hpp"
#include "learner/run_dir/learning_curve.hpp"

namespace masa::learner {
namespace {

// RunningMeanStd's default epsilon: the broadcast std is sqrt(var + eps), what the learner divides by.
constexpr double kObsEps = 1e-5;

model::ModelConfig modelConfigOf(const config::RunConfig& rc) {
  model::ModelConfig m = rc.model;
  m.method = rc.method;  // the run's method is authoritative
  return m;
}

template <class T>
T readPod(std::istream& is, const std::string& source) {
  T v{};
  if (!io::readPod(is, v)) throw std::runtime_error(source + ": truncated checkpoint");
  return v;
}

// The body's head: lr and the minibatch shuffle (the model and Adam follow).
double readLrAndOrder(std::istream& is, const std::string& source, std::vector<int>* order) {
  const double lr = readPod<double>(is, source);
  const uint64_t n = readPod<uint64_t>(is, source);
  if (n > (1ull << 31)) throw std::runtime_error(source + ": corrupt shuffle order");
  std::vector<int> o(n);
  if (!io::readArray(is, o.data(), n)) throw std::runtime_error(source + ": truncated checkpoint");
  if (order) *order = std::move(o);
  return lr;
}

}  // namespace

PpoAlgorithm::PpoAlgorithm(const config::RunConfig& rc, Rng& rng, cluster::Communicator& ranks) : rc_(rc) {
  if (rc.learner != "ppo")
    throw std::runtime_error("learner: " + rc.learner + " is not built into this program (masa_learner and masa_train run it)");
  const int64_t batch_samples = static_cast<int64_t>(rc.rollout.num_envs) * rc.rollout.horizon;
  // The user's numbers, not our bug: said without a source line.
  if (rc.ppo.minibatch_size <= 0 || batch_samples % rc.ppo.minibatch_size != 0)
    throw std::runtime_error("ppo.minibatch_size " + std::to_string(rc.ppo.minibatch_size) +
                             " must divide the batch, ppo.num_envs x ppo.horizon = " + std::to_string(batch_samples));
  const auto spec = sym::SymmetrySpec::load(rc.spec_path);
  model_ = std::make_unique<model::ActorCritic<float>>(spec, modelConfigOf(rc));
  model_->initialize(rng);
  nn::AdamConfig<float> adam_cfg;
  adam_cfg.lr = static_cast<float>(rc.ppo.learning_rate);
  adam_ = std::make_unique<nn::Adam<float>>(model_->params(), adam_cfg);
  trainer_ = std::make_unique<ppo::PpoTrainer>(*model_, *adam_, rc.ppo, ranks);
}

std::unique_ptr<Algorithm> makePpoAlgorithm(const config::RunConfig& rc, Rng& rng, cluster::Communicator& ranks) {
  return std::make_unique<PpoAlgorithm>(rc, rng, ranks);
}

LearnFigures PpoAlgorithm::learn(rollout::RolloutBuffer& batch, std::span<const int64_t>, Rng& rng) {
  trainer_->prepare(batch);
  if (!restored_order_.empty()) {
    // A resumed run continues the shuffle of the run it resumes (see PpoTrainer::shuffleOrder).
    if (restored_order_.size() == trainer_->shuffleOrder().size()) trainer_->shuffleOrder() = restored_order_;
    restored_order_.clear();
  }
  const ppo::PpoStats p = trainer_->optimize(batch, rng);
  LearnFigures f;
  f.actor_loss = p.actor_loss;
  f.critic_loss = p.critic_loss;
  f.entropy = p.entropy;
  f.bounds_loss = p.bounds_loss;
  f.sym_policy_loss = p.sym_policy_loss;
  f.sym_value_loss = p.sym_value_loss;
  f.kl = p.kl;
  f.lr = p.lr;
  f.grad_norm = p.grad_norm;
  f.explained_variance = p.explained_variance;
  return f;
}

std::string PpoAlgorithm::progressFigures(const LearnFigures& f) const {
  char line[160];
  std::snprintf(line, sizeof(line), "kl %.5f  lr %.2e  actor %.4f  critic %.4f", f.kl, f.lr, f.actor_loss, f.critic_loss);
  return line;
}

std::string PpoAlgorithm::curveScript(const std::string& title, const std::vector<std::string>& term_names,
                                      bool has_success) const {
  return learningCurveScript(title, term_names, has_success, true);
}

void PpoAlgorithm::fillPolicyMessage(masa::lcmt_policy_params& m) const {
  // The policy prefix only: the critic is the learner's business, and it halves the broadcast.
  const auto& p = model_->params().values();
  m.num_params = model_->policyParamCount();
  m.params.assign(p.data(), p.data() + m.num_params);
  if (model_->config().normalize_obs) {
    auto& norm = model_->obsNormalizer();
    m.obs_dim = norm.dim();
    m.obs_mean.resize(norm.dim());
    m.obs_std.resize(norm.dim());
    for (int d = 0; d < norm.dim(); ++d) {
      m.obs_mean[d] = static_cast<float>(norm.mean()(d));
      m.obs_std[d] = static_cast<float>(std::sqrt(norm.var()(d) + kObsEps));
    }
  } else {
    m.obs_dim = 0;
  }
}

void PpoAlgorithm::savePolicyFile(const std::string& path) const { policy::savePolicyFile(path, rc_, *model_); }

void PpoAlgorithm::saveCheckpointBody(std::ostream& os) const {
  io::writePod(os, trainer_->learningRate().lr());
  const std::vector<int>& order = trainer_->shuffleOrder();
  io::writePod(os, static_cast<uint64_t>(order.size()));
  io::writeArray(os, order.data(), order.size());
  model_->save(os);
  adam_->save(os);
}

void PpoAlgorithm::loadCheckpointBody(std::istream& is, const std::string& source) {
  const double lr = readLrAndOrder(is, source, &restored_order_);
  model_->load(is, source);
  adam_->load(is);
  if (is.peek() != std::char_traits<char>::eof())
    throw std::runtime_error(source + ": bytes after the optimizer (corrupt checkpoint)");
  trainer_->learningRate().setLr(lr);
  adam_->config().lr = static_cast<float>(lr);
}

uint64_t PpoAlgorithm::agreementHash() const {
  const auto& p = model_->params().values();
  uint64_t h = cluster::hashBytes(p.data(), sizeof(float) * static_cast<std::size_t>(p.size()));
  for (const auto* norm : {&model_->obsNormalizer(), &model_->valueNormalizer()}) {
    h = cluster::hashBytes(norm->mean().data(), sizeof(double) * static_cast<std::size_t>(norm->dim()), h);
    h = cluster::hashBytes(norm->var().data(), sizeof(double) * static_cast<std::size_t>(norm->dim()), h);
  }
  const double lr = trainer_->learningRate().lr();
  return cluster::hashBytes(&lr, sizeof lr, h);
}

void loadPpoCheckpointModel(const std::string& path, model::ActorCritic<float>& model) {
  const CheckpointState s = readCheckpoint(path);
  if (s.kind != "ppo")
    throw std::runtime_error(path + ": the checkpoint of a run with learner: " + s.kind + " holds no policy to evaluate: evaluate " +
                             "the policy.bin beside it");
  std::istringstream is(s.body, std::ios::binary);
  readLrAndOrder(is, path, nullptr);
  model.load(is, path);
}

}  // namespace masa::learner
