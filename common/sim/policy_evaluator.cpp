#include "common/sim/policy_evaluator.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

#include "common/core/check.hpp"
#include "common/model/diag_gaussian.hpp"

namespace masa::task {
namespace {

Moments moments(const std::vector<double>& x) {
  Moments m;
  if (x.empty()) return m;
  double s = 0;
  for (double v : x) s += v;
  m.mean = s / static_cast<double>(x.size());
  double q = 0;
  for (double v : x) q += (v - m.mean) * (v - m.mean);
  m.std = x.size() > 1 ? std::sqrt(q / static_cast<double>(x.size() - 1)) : 0.0;
  m.min = *std::min_element(x.begin(), x.end());
  m.max = *std::max_element(x.begin(), x.end());
  return m;
}

}  // namespace

PolicyEvaluator::PolicyEvaluator(const TaskFactory& factory, model::ActorCritic<float>& model)
    : factory_(&factory), model_(&model) {}

EvalSummary PolicyEvaluator::run(const EvalOptions& o, const StepHook& hook, const TransitionHook& transitions) {
  MASA_CHECK(o.episodes > 0, "evaluation needs at least one episode, got " << o.episodes);
  // A squashed (SAC) policy's noise depends on the observation and is not in its file.
  MASA_CHECK(o.deterministic || model_->config().squash == model::ActionSquash::kNone,
             "a squashed (SAC) policy file holds its deterministic action tanh(mean) only: it cannot be sampled");
  const int n = o.episodes;
  std::vector<std::unique_ptr<Task>> envs(n);
  std::vector<Rng> rngs;
  rngs.reserve(n);
  for (int k = 0; k < n; ++k) {
    envs[k] = factory_->create();
    rngs.emplace_back(o.seed + static_cast<uint64_t>(k));
    envs[k]->reset(rngs[k]);
  }
  const Task& first = *envs[0];
  MASA_CHECK(first.obsDim() == model_->obsDim() && first.actDim() == model_->actDim(),
             "the task has obs " << first.obsDim() << " / act " << first.actDim() << ", the policy "
                                 << model_->obsDim() << " / " << model_->actDim());
  const int obs_dim = first.obsDim(), act_dim = first.actDim();
  const int limit = o.max_steps > 0 ? std::min(o.max_steps, first.maxEpisodeSteps()) : first.maxEpisodeSteps();

  EvalSummary s;
  s.term_names = first.rewardTermNames();
  s.progress_names = first.progressNames();
  s.physics_names = first.physicsDrawNames();
  s.episodes.resize(n);
  Vec<float> log_std(act_dim);
  model_->logStd(log_std);

  std::vector<int> active(n);
  for (int k = 0; k < n; ++k) active[k] = k;
  Mat<float> obs(obs_dim, n), act(act_dim, n);
  std::vector<char> done(n, 0);
  std::vector<StepOutcome> outcomes(n);
  for (int t = 0; t < limit && !active.empty(); ++t) {
    const int m = static_cast<int>(active.size());
    for (int j = 0; j < m; ++j) envs[active[j]]->observe(obs.col(j).data());
    // One column at a time: Eigen multiplies a single column (GEMV) and a batch (GEMM) with
    // different summation orders, which on AVX2 round differently, and an episode must not
    // depend on how many others run beside it.
    for (int j = 0; j < m; ++j) act.col(j) = model_->actMean(obs.col(j));
    if (!o.deterministic)
      for (int j = 0; j < m; ++j) {  // each episode's own generator: independent of the batch's make-up
        Mat<float> mean = act.col(j);
        model::gaussian::sample<float>(mean, log_std, rngs[active[j]], act.col(j));
      }
#pragma omp parallel for num_threads(std::max(1, std::min(o.threads, m))) schedule(static)
    for (int j = 0; j < m; ++j) {
      const StepOutcome out = envs[active[j]]->step(act.col(j).data());
      outcomes[active[j]] = out;
      done[active[j]] = out.terminated || out.truncated || t + 1 == limit;
    }
    if (hook)
      for (int j = 0; j < m; ++j) hook(active[j], t, *envs[active[j]], done[active[j]] != 0);
    if (transitions)
      for (int j = 0; j < m; ++j) {
        const int k = active[j];
        StepOutcome out = outcomes[k];
        out.truncated = done[k] && !out.terminated;  // max_steps cuts like the time limit
        transitions({k, t, obs.col(j).data(), act.col(j).data(), out, done[k] != 0}, *envs[k]);
      }
    std::vector<int> still;
    still.reserve(m);
    for (int k : active) {
      if (!done[k]) {
        still.push_back(k);
        continue;
      }
      const Task& env = *envs[k];
      const EpisodeStats& st = env.episode();
      EpisodeResult& r = s.episodes[k];
      r.seed = o.seed + static_cast<uint64_t>(k);
      r.ret = st.ret;
      r.length = st.length;
      r.terminated = st.terminated;
      r.truncated = !st.terminated;  // the time limit, or max_steps
      r.success = st.has_success ? (st.success ? 1 : 0) : -1;
      r.terms = st.term_sums;
      r.physics = st.physics;
      r.progress.assign(s.progress_names.size(), 0.0);
      if (!r.progress.empty()) env.progress(r.progress.data());
    }
    active.swap(still);
  }

  std::vector<double> col(n);
  auto gather = [&](auto get) {
    for (int k = 0; k < n; ++k) col[k] = get(s.episodes[k]);
    return moments(col);
  };
  s.ret = gather([](const EpisodeResult& r) { return r.ret; });
  s.length = gather([](const EpisodeResult& r) { return static_cast<double>(r.length); });
  for (size_t i = 0; i < s.term_names.size(); ++i) s.terms.push_back(gather([&](const EpisodeResult& r) { return r.terms[i]; }));
  for (size_t i = 0; i < s.progress_names.size(); ++i)
    s.progress.push_back(gather([&](const EpisodeResult& r) { return r.progress[i]; }));
  for (size_t i = 0; i < s.physics_names.size(); ++i)
    s.physics.push_back(gather([&](const EpisodeResult& r) { return r.physics[i]; }));
  int measured = 0, succeeded = 0;
  for (const EpisodeResult& r : s.episodes) {
    if (r.success >= 0) ++measured;
    if (r.success == 1) ++succeeded;
    if (r.truncated) ++s.time_limit_reached;
  }
  s.success_rate = measured > 0 ? static_cast<double>(succeeded) / measured : -1.0;
  return s;
}

std::string formatSummary(const EvalSummary& s) {
  std::ostringstream os;
  char line[160];
  const int n = static_cast<int>(s.episodes.size());
  auto row = [&](const std::string& name, const Moments& m) {
    std::snprintf(line, sizeof line, "| %-24s | %10.3f | %9.3f | %10.3f | %10.3f |\n", name.c_str(), m.mean, m.std, m.min,
                  m.max);
    os << line;
  };
  os << "| over " << n << " episodes" << std::string(n < 10 ? 12 : 11, ' ') << "|       mean |       std |        min |        max |\n";
  os << "|--------------------------|------------|-----------|------------|------------|\n";
  row("return", s.ret);
  row("length (steps)", s.length);
  for (size_t i = 0; i < s.progress_names.size(); ++i) row(s.progress_names[i], s.progress[i]);
  for (size_t i = 0; i < s.term_names.size(); ++i) row("reward: " + s.term_names[i], s.terms[i]);
  for (size_t i = 0; i < s.physics_names.size(); ++i) row(s.physics_names[i], s.physics[i]);
  std::snprintf(line, sizeof line, "time limit reached in %d of %d episodes", s.time_limit_reached, n);
  os << line;
  if (s.success_rate >= 0) {
    std::snprintf(line, sizeof line, "; success rate %.2f", s.success_rate);
    os << line;
  }
  os << "\n";
  return os.str();
}

}  // namespace masa::task
