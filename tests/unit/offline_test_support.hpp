// Datasets and configurations shared by the offline-learning tests (BC, IQL, SASA-data).
#pragma once

#include "common/dataset/transition_dataset.hpp"
#include "common/model/actor_critic.hpp"
#include "learner/offline/offline_config.hpp"
#include "model_test_support.hpp"

namespace masa::test {

// Episodes of random transitions of a spec's dimensions (next_obs continues obs; the last step of
// each episode is a time-out, every third episode terminates instead). Returns set per episode.
inline dataset::TransitionDataset randomDataset(const sym::SymmetrySpec& spec, int episodes, int length, Rng& rng) {
  dataset::TransitionDataset d;
  d.task = "synthetic";
  d.obs_dim = spec.obsDim();
  d.act_dim = spec.actDim();
  const int n = episodes * length;
  d.obs = randomMatrix<float>(d.obs_dim, n, rng, 1.3, 0.4);
  d.actions = randomMatrix<float>(d.act_dim, n, rng, 0.8);
  d.rewards = randomMatrix<float>(n, 1, rng).col(0);
  d.next_obs.resize(d.obs_dim, n);
  d.policy_names = {"random"};
  for (int e = 0; e < episodes; ++e) {
    dataset::EpisodeInfo info;
    info.episode_id = 100 + e;
    info.start = static_cast<int64_t>(e) * length;
    info.length = length;
    info.ret = d.rewards.segment(info.start, length).sum();
    d.episodes.push_back(info);
    for (int t = 0; t < length; ++t) {
      const int k = e * length + t;
      const bool last = t == length - 1;
      d.next_obs.col(k) = last ? randomMatrix<float>(d.obs_dim, 1, rng).col(0) : Vec<float>(d.obs.col(k + 1));
      d.terminals.push_back(last && e % 3 == 2);
      d.timeouts.push_back(last && e % 3 != 2);
    }
  }
  d.validate();
  return d;
}

// A model with small networks for tests. last_layer_scale 1 gives O(1) outputs from the start
// (gradient and symmetry checks); the default keeps the small initial actions of training.
inline model::ModelConfig smallOfflineModel(model::Method method, std::vector<int> policy_hidden,
                                            std::vector<int> critic_hidden, double last_layer_scale = 0.01) {
  model::ModelConfig m;
  m.method = method;
  m.policy_hidden = std::move(policy_hidden);
  m.critic_hidden = std::move(critic_hidden);
  m.policy_last_layer_scale = last_layer_scale;
  return m;
}

// The offline defaults with small numbers for tests.
inline offline::OfflineConfig smallOfflineConfig(offline::Algo algo, long long steps) {
  offline::OfflineConfig c;
  c.algo = algo;
  c.steps = steps;
  c.q_hidden = {32, 16};
  return c;
}

}  // namespace masa::test
