// What masa_sac's run (sac_run.hpp) needs of an off-policy algorithm on the shared SAC policy
// network (sac_policy.hpp) and twin Q: collect with it, take a gradient step on a replay batch,
// save and load everything a resumed run needs. SAC (sac_trainer.hpp) and TD3 (td3_trainer.hpp).
#pragma once

#include <iosfwd>

#include "common/core/types.hpp"
#include "learner/sac/replay_buffer.hpp"

namespace masa::sac {

// One gradient step's figures (the metrics row averages them). SAC fills all; TD3 has no
// temperature (alpha and its loss 0, entropy NaN) and reports its last actor step's loss.
struct SacStats {
  double q_loss = 0, actor_loss = 0, alpha_loss = 0, symmetry_loss = 0;
  double alpha = 0, mean_q = 0, entropy = 0;  // entropy: -mean log pi of the actor step's actions
};

template <typename S>
class OffPolicyTrainer {
 public:
  virtual ~OffPolicyTrainer() = default;
  // The action to collect with for raw observations (act_dim x B), noise from rng.
  virtual void explore(const ConstMatRef<S>& raw_obs, Rng& rng, MatRef<S> actions) = 0;
  virtual SacStats step(const ReplayBatch<S>& batch, Rng& rng) = 0;
  virtual long long steps() const = 0;  // gradient steps taken
  virtual void save(std::ostream& os) const = 0;
  virtual void load(std::istream& is) = 0;
};

}  // namespace masa::sac
