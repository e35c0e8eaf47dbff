// Data-parallel PPO over MPI, run as `mpirun -np 2 masa_test_ppo_ranks` (tests/CMakeLists.txt):
//  1. Two learner ranks, each with its share of the environments, against one learner with all of
//     them (rank 0 runs both), with the learner's own settings (Adam's eps 1e-8), after each of
//     kUpdates updates: both normalizers, the learning rate and the KL agree within kTolerance, the
//     parameters within kTolerance (SA, SASA) or kMasaParamsTolerance (MASA); the ranks among
//     themselves bit for bit (the learner's hash check relies on it). MASA and SASA, equal shares
//     and a short rank (lost chunks).
//  2. Ranks whose parameters differ (one weight of rank 1 nudged) are caught by the parameter hash
//     check on every rank, which names rank 1; identical ranks pass it.
// Exit status 0 and "PASS" on rank 0 when every check holds.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "common/cluster/mpi_job.hpp"
#include "common/cluster/rank_agreement.hpp"
#include "common/model/diag_gaussian.hpp"
#include "learner/ppo/ppo_trainer.hpp"
#include "../unit/model_test_support.hpp"

namespace masa {
namespace {

// Relative to max(1, |reference|): the ranks' sums add the same terms in another order, so they
// round differently. Adam (eps 1e-8) divides each step by the gradient's running magnitude: a
// weight whose gradient vanishes (in MASA the mirror cancels some exactly) steps by up to the
// learning rate in the direction of that rounding, in one learner as in N ranks. Measured with these
// settings: MASA's parameters 7e-4 after one update, 1.1e-3 after three; SA 1.4e-6, SASA 2e-7; the
// normalizers, learning rate and KL below 1e-7. A real fault (a share weighted wrongly, a statistic
// not reduced) is of the order of the training's own steps (kMoved and more).
constexpr double kTolerance = 1e-5;
constexpr double kMasaParamsTolerance = 2e-3;
constexpr double kMoved = 2e-2;  // the least the parameters move in one update here
constexpr int kHorizon = 4, kUpdates = 3;

int failures = 0;
void expect(bool ok, const std::string& what) {
  if (!ok) {
    ++failures;
    std::fprintf(stderr, "FAILED: %s\n", what.c_str());
  }
}

config::PpoConfig ppoConfig() {
  config::PpoConfig c;
  c.minibatch_size = 32;  // 4 minibatches of the whole batch, 3 mini-epochs: 12 Adam steps an update
  c.mini_epochs = 3;
  c.learning_rate = 3e-3;
  c.lr_schedule = "adaptive";  // the KL decides the rate: it must be reduced across ranks
  c.kl_threshold = 0.008;
  return c;
}

struct Learner {
  Learner(model::Method method, int num_envs, cluster::Communicator& ranks)
      : spec(test::spec(test::kMirrorSpec, "mirror")) {
    model::ModelConfig mc;
    mc.method = method;
    mc.policy_hidden = {32, 32};
    mc.critic_hidden = {32, 32};
    model = std::make_unique<model::ActorCritic<float>>(spec, mc);
    Rng init(11);
    model->initialize(init);
    adam = std::make_unique<nn::Adam<float>>(model->params(), nn::AdamConfig<float>{});  // the learner's defaults
    trainer = std::make_unique<ppo::PpoTrainer>(*model, *adam, ppoConfig(), ranks);
    buffer = std::make_unique<rollout::RolloutBuffer>(num_envs, kHorizon, spec.obsDim(), spec.actDim());
  }
  sym::SymmetrySpec spec;
  std::unique_ptr<model::ActorCritic<float>> model;
  std::unique_ptr<nn::Adam<float>> adam;
  std::unique_ptr<ppo::PpoTrainer> trainer;
  std::unique_ptr<rollout::RolloutBuffer> buffer;
};

// A whole batch of `envs` environments from `rng` alone (so every rank makes the same one): random
// observations and rewards, actions from the reference policy, terminations and time-outs.
void fillBatch(Learner& l, Rng& rng) {
  rollout::RolloutBuffer& b = *l.buffer;
  b.clear();
  b.obs() = test::randomMatrix<float>(b.obsDim(), b.size(), rng);
  b.bootstrapObs() = test::randomMatrix<float>(b.obsDim(), b.numEnvs(), rng);
  b.means() = test::randomMatrix<float>(b.actDim(), b.size(), rng) * 0.3f;
  Vec<float> log_std = Vec<float>::Constant(b.actDim(), -0.5f);
  b.envLogStds().colwise() = log_std;
  model::gaussian::sample<float>(b.means(), log_std, rng, b.actions());
  model::gaussian::logProb<float>(b.means(), log_std, b.actions(), b.logProbs());
  std::uniform_real_distribution<float> u(0.f, 1.f);
  b.terminated().setZero();
  b.truncated().setZero();
  for (int t = 0; t < b.horizon(); ++t)
    for (int e = 0; e < b.numEnvs(); ++e) {
      b.rewards()(t, e) = u(rng) * 2.f - 1.f + b.obs()(1, b.column(t, e));
      const float p = u(rng);
      if (p < 0.1f) {
        b.terminated()(t, e) = 1;
      } else if (p < 0.15f) {
        b.truncated()(t, e) = 1;
        b.addFinalObs(t, e, test::randomMatrix<float>(b.obsDim(), 1, rng));
      }
    }
}

// Environments [first, first + out.numEnvs()) of `in`, with their time-outs.
void copyEnvs(const rollout::RolloutBuffer& in, int first, rollout::RolloutBuffer& out) {
  out.clear();
  const int n = out.numEnvs();
  for (int t = 0; t <= in.horizon(); ++t)
    for (int e = 0; e < n; ++e) {
      std::copy_n(in.data().obsAt(t, first + e), in.obsDim(), out.data().obsAt(t, e));
      if (t == in.horizon()) continue;
      out.actions().col(out.column(t, e)) = in.actions().col(in.column(t, first + e));
      out.means().col(out.column(t, e)) = in.means().col(in.column(t, first + e));
      out.logProbs()(0, out.column(t, e)) = in.logProbs()(0, in.column(t, first + e));
      out.rewards()(t, e) = in.rewards()(t, first + e);
      out.terminated()(t, e) = in.terminated()(t, first + e);
      out.truncated()(t, e) = in.truncated()(t, first + e);
    }
  for (int e = 0; e < n; ++e) out.envLogStds().col(e) = in.envLogStds().col(first + e);
  for (int k = 0; k < in.numFinalObs(); ++k) {
    const auto f = in.finalObsEntry(k);
    if (f.e >= first && f.e < first + n) out.addFinalObs(f.t, f.e - first, in.finalObs().col(k));
  }
}

double relativeGap(const Eigen::VectorXd& a, const Eigen::VectorXd& ref) {
  double worst = 0;
  for (Eigen::Index i = 0; i < ref.size(); ++i)
    worst = std::max(worst, std::abs(a(i) - ref(i)) / std::max(1.0, std::abs(ref(i))));
  return worst;
}

// Ranks hold `shares[rank]` environments each; the reference learner all of them, in rank order.
void ranksTrainAsOneLearner(cluster::Communicator& ranks, model::Method method, const std::vector<int>& shares,
                            const std::string& name) {
  int total = 0, first = 0;
  for (int r = 0; r < static_cast<int>(shares.size()); ++r) {
    if (r < ranks.rank()) first += shares[r];
    total += shares[r];
  }
  Learner whole(method, total, cluster::soloCommunicator());  // the batch maker, and rank 0's reference
  Learner part(method, shares[ranks.rank()], ranks);
  Rng data(99), shuffle_whole(7), shuffle_part(7);
  ppo::PpoStats ref_stats, part_stats;
  auto vec = [](const Vec<float>& v) { return Eigen::VectorXd(v.cast<double>()); };
  const Eigen::VectorXd initial = vec(whole.model->params().values());
  for (int u = 1; u <= kUpdates; ++u) {
    fillBatch(whole, data);
    copyEnvs(*whole.buffer, first, *part.buffer);
    part_stats = part.trainer->update(*part.buffer, shuffle_part);
    ref_stats = whole.trainer->update(*whole.buffer, shuffle_whole);  // every rank: it also feeds the batches
    const double params = relativeGap(vec(part.model->params().values()), vec(whole.model->params().values()));
    const double obs_mean = relativeGap(part.model->obsNormalizer().mean(), whole.model->obsNormalizer().mean());
    const double obs_var = relativeGap(part.model->obsNormalizer().var(), whole.model->obsNormalizer().var());
    const double value_norm = relativeGap(part.model->valueNormalizer().var(), whole.model->valueNormalizer().var()) +
                              relativeGap(part.model->valueNormalizer().mean(), whole.model->valueNormalizer().mean());
    const double lr = std::abs(part_stats.lr - ref_stats.lr) / ref_stats.lr;
    const double kl = std::abs(part_stats.kl - ref_stats.kl) / std::max(1e-12, ref_stats.kl);
    const double moved = relativeGap(vec(whole.model->params().values()), initial);
    if (ranks.rank() == 0)
      std::printf("%-34s gaps after %d update(s): params %.2e, obs mean %.2e, var %.2e, value norm %.2e, lr %.2e, "
                  "kl %.2e (params moved %.2e; lr %.3g)\n",
                  name.c_str(), u, params, obs_mean, obs_var, value_norm, lr, kl, moved, ref_stats.lr);
    const std::string after = " after " + std::to_string(u) + " update(s)";
    expect(moved > kMoved, name + ": training moved the parameters" + after);
    expect(params <= (method == model::Method::kMasa ? kMasaParamsTolerance : kTolerance), name + ": parameters" + after);
    expect(obs_mean <= kTolerance && obs_var <= kTolerance, name + ": observation normalizer" + after);
    expect(value_norm <= kTolerance, name + ": value normalizer" + after);
    expect(lr <= kTolerance, name + ": learning rate" + after);
    expect(kl <= kTolerance, name + ": KL" + after);
    expect(part_stats.minibatches == ref_stats.minibatches, name + ": minibatch count" + after);
  }
  // The ranks among themselves: bit for bit, or the learner's hash check would stop the run.
  const auto& p = part.model->params().values();
  std::string disagreement;
  try {
    cluster::requireSameOnEveryRank(ranks, cluster::hashBytes(p.data(), sizeof(float) * static_cast<std::size_t>(p.size())),
                                    "parameters");
  } catch (const cluster::RankDisagreement& e) {
    disagreement = e.what();
  }
  expect(disagreement.empty(), name + ": the ranks' parameters are not bit for bit the same: " + disagreement);
}

void hashCheckNamesThePerturbedRank(cluster::Communicator& ranks) {
  Learner l(model::Method::kMasa, 8, ranks);
  auto& p = l.model->params().values();
  const auto hash = [&] { return cluster::hashBytes(p.data(), sizeof(float) * static_cast<std::size_t>(p.size())); };
  bool threw = false;
  try {
    cluster::requireSameOnEveryRank(ranks, hash(), "parameters");
  } catch (const cluster::RankDisagreement&) {
    threw = true;
  }
  expect(!threw, "identical ranks pass the hash check");
  if (ranks.rank() == 1) p(3) = std::nextafter(p(3), 1.f);  // one ulp of one weight
  std::string message;
  try {
    cluster::requireSameOnEveryRank(ranks, hash(), "parameters");
  } catch (const cluster::RankDisagreement& e) {
    message = e.what();
  }
  if (ranks.rank() == 0) std::printf("perturbed rank 1: \"%s\"\n", message.c_str());
  expect(message.find("rank 1 disagrees with rank 0") != std::string::npos,
         "a one-ulp change on rank 1 is caught on every rank and names rank 1 (got \"" + message + "\")");
}

}  // namespace
}  // namespace masa

int main() {
  using namespace masa;
  cluster::MpiJob job(cluster::Role::kLearner);
  cluster::Communicator& ranks = job.learners();
  if (ranks.size() != 2) {
    std::fprintf(stderr, "run with 2 learner ranks (mpirun -np 2), not %d\n", ranks.size());
    return 2;
  }
  ranksTrainAsOneLearner(ranks, model::Method::kMasa, {16, 16}, "MASA, 16 + 16 environments");
  ranksTrainAsOneLearner(ranks, model::Method::kSasa, {16, 16}, "SASA, 16 + 16 environments");
  ranksTrainAsOneLearner(ranks, model::Method::kSa, {16, 9}, "SA, 16 + 9 (a short rank)");
  hashCheckNamesThePerturbedRank(ranks);
  const std::vector<int64_t> all = ranks.gather(failures);
  int64_t total = 0;
  for (int64_t f : all) total += f;
  if (ranks.rank() == 0) std::printf(total == 0 ? "PASS\n" : "FAIL: %lld checks failed\n", static_cast<long long>(total));
  return total == 0 ? 0 : 1;
}
