#include "common/dataset/policy_recorder.hpp"

#include <vector>

namespace masa::dataset {

int64_t episodeId(const std::string& policy_name, uint64_t seed) {
  uint32_t h = 2166136261u;  // FNV-1a
  for (unsigned char c : policy_name) h = (h ^ c) * 16777619u;
  return static_cast<int64_t>((static_cast<uint64_t>(h) << 32) | (seed & 0xffffffffu));
}

task::EvalSummary recordEpisodes(const task::TaskFactory& factory, model::ActorCritic<float>& model,
                                 const RecordOptions& options, const std::function<void(const EpisodeRecord&)>& sink) {
  const int n = options.eval.episodes, od = model.obsDim(), ad = model.actDim();
  // Per episode: columns appended as steps come (obs o_t, action a_t), closed with o_T.
  std::vector<std::vector<float>> obs(n), actions(n);
  std::vector<std::vector<float>> rewards(n);
  std::vector<float> next(static_cast<size_t>(od));
  auto hook = [&](const task::PolicyEvaluator::Transition& tr, const task::Task& env) {
    obs[tr.k].insert(obs[tr.k].end(), tr.obs, tr.obs + od);
    actions[tr.k].insert(actions[tr.k].end(), tr.action, tr.action + ad);
    rewards[tr.k].push_back(static_cast<float>(tr.outcome.reward));
    if (!tr.last) return;
    env.observe(next.data());
    obs[tr.k].insert(obs[tr.k].end(), next.begin(), next.end());
    EpisodeRecord e;
    const uint64_t seed = options.eval.seed + static_cast<uint64_t>(tr.k);
    e.task = env.name();
    e.episode_id = episodeId(options.policy_name, seed);
    e.policy_name = options.policy_name;
    const int T = static_cast<int>(rewards[tr.k].size());
    e.obs = Eigen::Map<Mat<float>>(obs[tr.k].data(), od, T + 1);
    e.actions = Eigen::Map<Mat<float>>(actions[tr.k].data(), ad, T);
    e.rewards = std::move(rewards[tr.k]);
    e.terminated = tr.outcome.terminated;
    e.truncated = tr.outcome.truncated;
    const task::EpisodeStats& st = env.episode();
    e.success = st.has_success ? (st.success ? 1 : 0) : -1;
    sink(e);
    std::vector<float>().swap(obs[tr.k]);  // free the finished episode's buffers
    std::vector<float>().swap(actions[tr.k]);
  };
  return task::PolicyEvaluator(factory, model).run(options.eval, {}, hook);
}

}  // namespace masa::dataset
