#include "common/dataset/episode_record.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace masa::dataset {

std::vector<masa::lcmt_transitions> episodeMessages(const EpisodeRecord& e, int max_steps, int64_t utime) {
  const int T = e.length(), od = static_cast<int>(e.obs.rows()), ad = static_cast<int>(e.actions.rows());
  if (T <= 0) throw std::invalid_argument("episode " + std::to_string(e.episode_id) + " has no transitions");
  if (e.obs.cols() != T + 1 || e.actions.cols() != T)
    throw std::invalid_argument("episode " + std::to_string(e.episode_id) + ": obs needs T + 1 columns, actions T");
  if (max_steps <= 0) throw std::invalid_argument("max_steps must be positive");
  std::vector<masa::lcmt_transitions> out;
  for (int t0 = 0; t0 < T; t0 += max_steps) {
    const int n = std::min(max_steps, T - t0);
    masa::lcmt_transitions m;
    m.utime = utime;
    m.task = e.task;
    m.episode_id = e.episode_id;
    m.policy_id = e.policy_id;
    m.policy_name = e.policy_name;
    m.step_offset = t0;
    m.num_steps = n;
    m.obs_dim = od;
    m.act_dim = ad;
    m.obs_len = (n + 1) * od;
    m.obs.assign(e.obs.data() + static_cast<int64_t>(t0) * od, e.obs.data() + static_cast<int64_t>(t0 + n + 1) * od);
    m.actions_len = n * ad;
    m.actions.assign(e.actions.data() + static_cast<int64_t>(t0) * ad, e.actions.data() + static_cast<int64_t>(t0 + n) * ad);
    m.rewards.assign(e.rewards.begin() + t0, e.rewards.begin() + t0 + n);
    m.last = t0 + n == T;
    m.terminated = m.last && e.terminated;
    m.truncated = m.last && e.truncated;
    m.success = m.last ? e.success : -1;
    out.push_back(std::move(m));
  }
  return out;
}

std::string checkTransitions(const masa::lcmt_transitions& m) {
  std::ostringstream why;
  auto finite = [](const std::vector<float>& v) {
    return std::all_of(v.begin(), v.end(), [](float x) { return std::isfinite(x); });
  };
  if (m.task.empty()) why << "no task name";
  else if (m.num_steps < 1) why << "num_steps " << m.num_steps << " < 1";
  else if (m.obs_dim < 1 || m.obs_dim > kMaxDatasetDim || m.act_dim < 1 || m.act_dim > kMaxDatasetDim)
    why << "dimensions obs " << m.obs_dim << " / act " << m.act_dim << " out of [1, " << kMaxDatasetDim << "]";
  else if (m.step_offset < 0) why << "negative step_offset " << m.step_offset;
  else if (m.policy_id < 0) why << "negative policy_id " << m.policy_id;
  else if (static_cast<int64_t>(m.obs_len) != (static_cast<int64_t>(m.num_steps) + 1) * m.obs_dim)
    why << "obs_len " << m.obs_len << " is not (num_steps + 1) * obs_dim = " << (int64_t{m.num_steps} + 1) * m.obs_dim;
  else if (static_cast<int64_t>(m.actions_len) != static_cast<int64_t>(m.num_steps) * m.act_dim)
    why << "actions_len " << m.actions_len << " is not num_steps * act_dim = " << int64_t{m.num_steps} * m.act_dim;
  else if (!finite(m.obs) || !finite(m.actions) || !finite(m.rewards)) why << "non-finite numbers";
  else if (!m.last && (m.terminated || m.truncated || m.success != -1))
    why << "terminated, truncated or success set on a message that is not its episode's last";
  else if (m.terminated && m.truncated) why << "both terminated and truncated";
  else if (m.success < -1 || m.success > 1) why << "success " << int{m.success} << " not in {-1, 0, 1}";
  return why.str();
}

}  // namespace masa::dataset
