#include "learner/offline/symmetry_augmentation.hpp"

#include <stdexcept>

namespace masa::offline {

dataset::TransitionDataset augmentWithSymmetricImages(const dataset::TransitionDataset& data,
                                                      const sym::SymmetrySpec& spec) {
  if (data.obs_dim != spec.obsDim() || data.act_dim != spec.actDim())
    throw std::runtime_error("dataset of " + data.task + " has obs/act dims " + std::to_string(data.obs_dim) + "/" +
                             std::to_string(data.act_dim) + ", the spec '" + spec.name() + "' " +
                             std::to_string(spec.obsDim()) + "/" + std::to_string(spec.actDim()));
  const int n_images = spec.numAgents();
  const Eigen::Index n = data.size();
  dataset::TransitionDataset out;
  out.task = data.task;
  out.obs_dim = data.obs_dim;
  out.act_dim = data.act_dim;
  out.policy_names = data.policy_names;
  out.obs.resize(data.obs_dim, n * n_images);
  out.next_obs.resize(data.obs_dim, n * n_images);
  out.actions.resize(data.act_dim, n * n_images);
  out.rewards.resize(n * n_images);
  out.terminals.reserve(n * n_images);
  out.timeouts.reserve(n * n_images);
  for (int i = 0; i < n_images; ++i) {
    const Eigen::Index at = i * n;
    spec.obsTransform(i).apply<float>(data.obs, out.obs.middleCols(at, n));
    spec.obsTransform(i).apply<float>(data.next_obs, out.next_obs.middleCols(at, n));
    spec.actTransform(i).apply<float>(data.actions, out.actions.middleCols(at, n));
    out.rewards.segment(at, n) = data.rewards;  // the symmetry leaves the reward unchanged (verified per task)
    out.terminals.insert(out.terminals.end(), data.terminals.begin(), data.terminals.end());
    out.timeouts.insert(out.timeouts.end(), data.timeouts.begin(), data.timeouts.end());
    for (dataset::EpisodeInfo e : data.episodes) {
      e.episode_id = e.episode_id * n_images + i;
      e.start += at;
      out.episodes.push_back(e);
    }
  }
  return out;
}

}  // namespace masa::offline
