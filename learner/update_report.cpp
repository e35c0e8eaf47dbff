#include "learner/update_report.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/transport/transport.hpp"

namespace masa::learner {

void summarizeEpisodes(const rollout::Rollout& d, UpdateReport& report, cluster::Communicator& ranks) {
  const int n_local = d.numEpisodes(), K = d.numTerms();
  // [episodes, return sum, length sum, with a success measure, succeeded, term sums...]
  std::vector<double> sums(5 + static_cast<std::size_t>(K), 0.0);
  sums[0] = n_local;
  for (int i = 0; i < n_local; ++i) {
    sums[1] += d.episode_return[i];
    sums[2] += d.episode_length[i];
    if (d.episode_success[i] >= 0) {
      sums[3] += 1;
      sums[4] += d.episode_success[i] == 1;
    }
    for (int k = 0; k < K; ++k) sums[5 + k] += d.episode_term_sums[static_cast<std::size_t>(i) * K + k];
  }
  if (ranks.size() > 1) ranks.sum(sums.data(), static_cast<int>(sums.size()));
  const int n = static_cast<int>(sums[0]);
  report.num_episodes = n;
  report.mean_return = sums[1];
  report.mean_length = sums[2];
  report.term_means.assign(sums.begin() + 5, sums.end());
  if (n > 0) {
    report.mean_return /= n;
    report.mean_length /= n;
    for (double& t : report.term_means) t /= n;
    report.last_episodes_update = report.update;
    report.last_return = report.mean_return;
    report.last_length = report.mean_length;
  } else {
    // No episode ended in this batch: there is no return to report (0 would read as one).
    report.mean_return = report.mean_length = std::nan("");
    for (double& t : report.term_means) t = std::nan("");
  }
  report.success_rate = sums[3] > 0 ? sums[4] / sums[3] : -1.0;
}

masa::lcmt_learner_stats statsMessage(const UpdateReport& report, const ReportColumns& columns, int64_t run_id,
                                      const DropStats& chunk_drops, int64_t stale_envs, int64_t overflow_envs) {
  masa::lcmt_learner_stats s;
  s.run_id = run_id;
  s.utime = transport::wallClockMicros();
  s.update = report.update;
  s.env_steps = report.env_steps;
  s.fps = static_cast<float>(report.fps);
  s.mean_episode_return = static_cast<float>(report.mean_return);
  s.mean_episode_length = static_cast<float>(report.mean_length);
  s.success_rate = static_cast<float>(report.success_rate);
  s.num_episodes = report.num_episodes;
  const LearnFigures& p = report.learned;
  s.actor_loss = static_cast<float>(p.actor_loss);
  s.critic_loss = static_cast<float>(p.critic_loss);
  s.entropy = static_cast<float>(p.entropy);
  s.bounds_loss = static_cast<float>(p.bounds_loss);
  s.symmetry_policy_loss = static_cast<float>(p.sym_policy_loss);
  s.symmetry_value_loss = static_cast<float>(p.sym_value_loss);
  s.kl = static_cast<float>(p.kl);
  s.learning_rate = static_cast<float>(p.lr);
  s.grad_norm = static_cast<float>(p.grad_norm);
  s.explained_variance = static_cast<float>(p.explained_variance);
  for (int r = 1; r < kNumDropReasons; ++r) {
    s.drop_reason_names.emplace_back(dropReasonName(static_cast<DropReason>(r)));
    s.drop_counts.push_back(chunk_drops.count[r]);
  }
  s.drop_reason_names.emplace_back("stale_in_collector");
  s.drop_counts.push_back(stale_envs);
  s.drop_reason_names.emplace_back("overflow_in_collector");
  s.drop_counts.push_back(overflow_envs);
  s.num_drop_reasons = static_cast<int32_t>(s.drop_counts.size());
  s.term_names = columns.term_names;
  s.num_terms = static_cast<int32_t>(s.term_names.size());
  for (int k = 0; k < s.num_terms; ++k)
    s.term_means.push_back(k < static_cast<int>(report.term_means.size()) ? static_cast<float>(report.term_means[k]) : 0.0f);
  return s;
}

std::vector<std::string> metricsHeader(const ReportColumns& columns) {
  std::vector<std::string> h{"update", "env_steps", "wall_time_s", "fps", "return", "length", "success"};
  for (const auto& t : columns.term_names) h.push_back("term_" + t);
  for (const char* n : {"actor_loss", "critic_loss", "entropy", "bounds_loss", "sym_policy", "sym_value", "kl", "lr",
                        "grad_norm", "explained_variance", "dropped_chunks", "dropped_envs", "eval_return", "eval_length",
                        "eval_success"})
    h.push_back(n);
  for (const auto& n : columns.progress_names) h.push_back("eval_" + n);
  return h;
}

void writeMetricsRow(std::ostream& f, const UpdateReport& report) {
  const LearnFigures& p = report.learned;
  f.precision(9);
  f << report.update << ',' << report.env_steps << ',' << report.wall_time_s << ','
    << report.fps << ',' << report.mean_return << ',' << report.mean_length << ',' << report.success_rate;
  for (double t : report.term_means) f << ',' << t;
  f << ',' << p.actor_loss << ',' << p.critic_loss << ',' << p.entropy << ',' << p.bounds_loss << ','
    << p.sym_policy_loss << ',' << p.sym_value_loss << ',' << p.kl << ',' << p.lr << ',' << p.grad_norm << ','
    << p.explained_variance << ',' << report.dropped_chunks << ',' << report.dropped_envs;
  f << ',' << report.eval_return << ',' << report.eval_length << ',' << report.eval_success;
  for (double v : report.eval_progress) f << ',' << v;
  f << '\n';
}

void printProgress(const UpdateReport& report, const ReportColumns& columns, int64_t max_updates,
                   double update_interval_s, int eval_episodes) {
  const int64_t done = report.update;  // updates done, this one included
  char eta[32] = "";
  if (max_updates > done) {
    const long remaining = std::lround(update_interval_s * static_cast<double>(max_updates - done));
    std::snprintf(eta, sizeof(eta), "  eta %ld:%02ld:%02ld", remaining / 3600, remaining / 60 % 60, remaining % 60);
  }
  char total[32] = "";
  if (max_updates > 0) std::snprintf(total, sizeof(total), "/%lld", static_cast<long long>(max_updates));
  char success[32] = "";  // only for tasks with a success notion
  if (report.success_rate >= 0) std::snprintf(success, sizeof(success), "  success %.2f", report.success_rate);
  char timing[64] = "";
  if (!std::isnan(report.learn_s) && !std::isnan(report.wait_s))
    std::snprintf(timing, sizeof(timing), "  learn %.3fs waited %.3fs", report.learn_s, report.wait_s);
  // The episodes that ended in this update, or that none did (with the last ones that did).
  char episodes[128];
  if (report.num_episodes > 0)
    std::snprintf(episodes, sizeof(episodes), "return %.3f  len %.1f", report.mean_return, report.mean_length);
  else if (report.last_episodes_update > 0)
    std::snprintf(episodes, sizeof(episodes), "no episode ended (update %lld's: return %.3f  len %.1f)",
                  static_cast<long long>(report.last_episodes_update), report.last_return, report.last_length);
  else
    std::snprintf(episodes, sizeof(episodes), "no episode ended yet");
  std::printf("update %lld%s  steps %lld  fps %.0f  %s%s  %s  dropped %lld chunks %lld envs%s%s\n",
              static_cast<long long>(done), total, static_cast<long long>(report.env_steps), report.fps, episodes, success,
              report.algorithm_figures.c_str(),
              static_cast<long long>(report.dropped_chunks), static_cast<long long>(report.dropped_envs), timing, eta);
  if (!std::isnan(report.eval_return)) {
    std::printf("  eval (policy mean, %d episodes): return %.3f  len %.1f", eval_episodes, report.eval_return,
                report.eval_length);
    if (!std::isnan(report.eval_success)) std::printf("  success %.2f", report.eval_success);
    for (size_t i = 0; i < columns.progress_names.size() && i < report.eval_progress.size(); ++i)
      std::printf("  %s %.3f", columns.progress_names[i].c_str(), report.eval_progress[i]);
    std::printf("\n");
  }
  std::fflush(stdout);
}

}  // namespace masa::learner
