#include "learner/sac/hindsight.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/core/config_section.hpp"
#include "common/core/check.hpp"

namespace masa::sac {

Hindsight::Hindsight(const config::RunConfig& rc, const SacConfig& sc, std::unique_ptr<task::GoalRelabeling> relabeling,
                     const sym::SymmetrySpec& spec)
    : share_(sc.her_share), window_(sc.her_future_window), relabeling_(std::move(relabeling)) {
  if (share_ > 0.0 && !relabeling_)
    config::sectionOf(rc, "sac").fail("her_share", "task " + rc.task +
                                                       " declares no goal to relabel (leave sac.her_share at 0)");
  if (!relabeling_) return;
  const auto& goal = relabeling_->goalEntries();
  const auto& achieved = relabeling_->achievedEntries();
  MASA_CHECK(!goal.empty() && goal.size() == achieved.size(), "a task's goal and achieved entries must pair up");
  for (int k : goal) MASA_CHECK(k >= 0 && k < spec.obsDim(), "goal entry " << k << " outside the observation");
  for (int k : achieved) MASA_CHECK(k >= 0 && k < spec.obsDim(), "achieved entry " << k << " outside the observation");
  checkGoalSymmetry(*relabeling_, spec);
}

void checkGoalSymmetry(const task::GoalRelabeling& relabeling, const sym::SymmetrySpec& spec) {
  const auto& goal = relabeling.goalEntries();
  const auto& achieved = relabeling.achievedEntries();
  const int d = spec.obsDim();
  auto position = [](const std::vector<int>& v, int j) {
    const auto it = std::find(v.begin(), v.end(), j);
    return it == v.end() ? -1 : static_cast<int>(it - v.begin());
  };
  for (int i = 0; i < spec.numAgents(); ++i) {
    const Eigen::MatrixXd t = spec.obsTransform(i).toDense();
    for (std::size_t k = 0; k < goal.size(); ++k) {
      for (int j = 0; j < d; ++j) {
        // Row goal[k] reads only goal entries, row achieved[k] only achieved ones, alike.
        const int jg = position(goal, j), ja = position(achieved, j);
        const double from_goal = t(goal[k], j), from_achieved = t(achieved[k], j);
        const bool ok = (jg >= 0 ? std::abs(from_goal - t(achieved[k], achieved[jg])) <= 1e-12 : from_goal == 0.0) &&
                        (ja >= 0 || from_achieved == 0.0);
        if (!ok)
          throw std::invalid_argument("the symmetry spec " + spec.name() + " acts on observation entry " +
                                      spec.obsNames()[goal[k]] + " (a goal) otherwise than on " +
                                      spec.obsNames()[achieved[k]] + " (what is achieved) under T_" +
                                      std::to_string(i) + ": relabeling would break the symmetry");
      }
    }
  }
}

template <typename S>
int Hindsight::sample(const ReplayBuffer& replay, int batch_size, int n_step, double discount, Rng& rng,
                       ReplayBatch<S>& batch) const {
  if (!enabled()) {
    replay.sample(batch_size, n_step, discount, rng, batch);
    return 0;
  }
  MASA_CHECK(replay.size() > 0, "cannot sample from an empty replay buffer");
  MASA_CHECK(batch_size > 0 && n_step > 0, "batch size and n must be positive");
  batch.resize(replay.obsDim(), replay.actDim(), batch_size);
  std::uniform_int_distribution<long long> pick(0, replay.size() - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto& achieved = relabeling_->achievedEntries();
  std::vector<float> goal(achieved.size());
  const GoalOverride override{relabeling_.get(), goal.data()};
  int relabeled = 0;
  for (int b = 0; b < batch_size; ++b) {
    const long long slot = pick(rng);
    if (unit(rng) < share_) {
      const float* reached = replay.nextObsAt(replay.futureSlot(slot, window_, rng));
      for (std::size_t k = 0; k < achieved.size(); ++k) goal[k] = reached[achieved[k]];
      replay.nStep(slot, n_step, discount, batch, b, &override);
      ++relabeled;
    } else {
      replay.nStep(slot, n_step, discount, batch, b);
    }
  }
  return relabeled;
}

template int Hindsight::sample<float>(const ReplayBuffer&, int, int, double, Rng&, ReplayBatch<float>&) const;
template int Hindsight::sample<double>(const ReplayBuffer&, int, int, double, Rng&, ReplayBatch<double>&) const;

}  // namespace masa::sac
