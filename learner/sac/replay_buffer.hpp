// The replay buffer of the off-policy learner: the last `capacity` transitions of ONE stream of
// environment steps in time order (an episode's steps consecutive, then the next episode's), kept
// in a ring that overwrites the oldest. Sampling draws indices uniformly from a passed-in generator
// and turns each into an n-step transition:
//   R = r_k + g r_(k+1) + ... + g^(m-1) r_(k+m-1),  bootstrap from o'_(k+m-1) with discount g^m,
// where m <= n stops early at the end of an episode: at a termination the discount is 0 (nothing
// follows a fall), at a time-out it is g^m from the truncated step's own next observation (the
// episode was cut, not ended), and at the newest stored step (what follows is not known yet).
//
// Each step also belongs to an episode (an id the caller gives, or the stream's own count), so
// that hindsight relabeling (hindsight.hpp) can draw a step stored later in the same episode even
// when other streams' steps lie between them (the distributed learner's stretches).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <unordered_map>
#include <vector>

#include "common/core/types.hpp"
#include "common/sim/goal_relabeling.hpp"

namespace masa::sac {

// A sampled minibatch; the learner's TD target is reward + discount * V(next_obs).
template <typename S>
struct ReplayBatch {
  Mat<S> obs, next_obs;  // obs_dim x B, raw (the learner normalizes)
  Mat<S> actions;        // act_dim x B, in [-1, 1]
  Mat<S> rewards;        // 1 x B: the n-step discounted sum
  Mat<S> discount;       // 1 x B: g^m, or 0 where the episode terminated within the m steps

  int size() const { return static_cast<int>(rewards.cols()); }
  void resize(int obs_dim, int act_dim, int batch);
};

// A goal written over the goal entries of a transition's observations, with the task's rewards
// and terminations for it (ReplayBuffer::nStep).
struct GoalOverride {
  const task::GoalRelabeling* relabeling = nullptr;
  const float* goal = nullptr;  // relabeling->goalEntries().size() values
};

class ReplayBuffer {
 public:
  // add()'s episode when the buffer holds one stream: the previous step's episode, or a new one
  // after a step that terminated or was truncated.
  static constexpr long long kContinueStream = -1;

  ReplayBuffer(int obs_dim, int act_dim, long long capacity);

  // One environment step: the observation the action was chosen from, the action, the reward, the
  // observation after the step (before any reset), how the episode ended if it did, and the
  // episode's id (>= 0; steps of one episode are added in order).
  void add(const float* obs, const float* action, double reward, const float* next_obs, bool terminated,
           bool truncated, long long episode = kContinueStream);

  long long size() const { return size_; }
  long long capacity() const { return capacity_; }
  long long added() const { return added_; }  // every add() since construction, overwritten ones too
  int obsDim() const { return obs_dim_; }
  int actDim() const { return act_dim_; }

  // Stored step `age` steps before the newest (0: the newest); for tests and the normalizer fit.
  long long slotOfAge(long long age) const;
  const float* obsAt(long long slot) const { return obs_.data() + slot * obs_dim_; }
  const float* nextObsAt(long long slot) const { return next_obs_.data() + slot * obs_dim_; }
  long long episodeAt(long long slot) const { return episode_[static_cast<size_t>(slot)]; }
  // The id the next add() with kContinueStream gives (0 for an empty buffer).
  long long continuingEpisode() const;

  // A step of slot's episode stored at or after it, uniformly among at most `window` + 1 of them
  // (window 0: to the newest stored step of the episode), drawn from rng.
  long long futureSlot(long long slot, long long window, Rng& rng) const;

  // batch_size n-step transitions at indices drawn from rng (one draw per sample, in order).
  template <typename S>
  void sample(int batch_size, int n_step, double discount, Rng& rng, ReplayBatch<S>& batch) const;
  // The n-step transition starting at a stored slot (what sample() does for each draw).
  // With a goal override, the observations carry that goal and each step's reward and termination
  // are the task's for it.
  template <typename S>
  void nStep(long long slot, int n_step, double discount, ReplayBatch<S>& batch, int column,
             const GoalOverride* goal = nullptr) const;

  // Contents and position, binary with size checks (resume continues with the same samples).
  // keep_newest >= 0 writes only the newest that many steps (a compact state that a resumed run
  // refills); they load as a buffer of that size, oldest first.
  void save(std::ostream& os, long long keep_newest = -1) const;
  void load(std::istream& is);  // throws std::runtime_error on a shape mismatch or truncation

 private:
  void reserveSlots(long long slots);
  // The episode index: each stored episode's slots in the order they were added.
  void forgetSlot(long long slot);  // before a slot is overwritten (always its episode's oldest)
  void rememberSlot(long long slot);
  void rebuildEpisodes();

  int obs_dim_, act_dim_;
  long long capacity_, allocated_ = 0;
  long long size_ = 0, next_ = 0, added_ = 0;  // next_: the slot the next add() writes
  std::vector<float> obs_, next_obs_, actions_, rewards_;
  std::vector<uint8_t> terminated_, truncated_;
  std::vector<long long> episode_;  // per slot
  std::vector<long long> place_;    // per slot: its index in its episode's list
  struct EpisodeSlots {
    std::vector<long long> slots;  // [first, size) are stored
    long long first = 0;
  };
  std::unordered_map<long long, EpisodeSlots> episodes_;
};

}  // namespace masa::sac
