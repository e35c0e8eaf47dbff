#include "learner/sac/replay_buffer.hpp"

#include <algorithm>
#include <cstring>
#include <istream>
#include <ostream>
#include <random>
#include <stdexcept>

#include "common/core/binary_io.hpp"
#include "common/core/check.hpp"

namespace masa::sac {

template <typename S>
void ReplayBatch<S>::resize(int obs_dim, int act_dim, int batch) {
  if (obs.rows() != obs_dim || obs.cols() != batch) {
    obs.resize(obs_dim, batch);
    next_obs.resize(obs_dim, batch);
  }
  if (actions.rows() != act_dim || actions.cols() != batch) actions.resize(act_dim, batch);
  if (rewards.cols() != batch) {
    rewards.resize(1, batch);
    discount.resize(1, batch);
  }
}

ReplayBuffer::ReplayBuffer(int obs_dim, int act_dim, long long capacity)
    : obs_dim_(obs_dim), act_dim_(act_dim), capacity_(capacity) {
  MASA_CHECK(obs_dim > 0 && act_dim > 0, "a replay buffer needs observations and actions");
  MASA_CHECK(capacity > 0, "replay capacity must be positive, got " << capacity);
}

void ReplayBuffer::reserveSlots(long long slots) {
  // Storage grows with use (doubling), so a large capacity costs memory only once it is filled.
  if (slots <= allocated_) return;
  const long long n = std::min(capacity_, std::max({slots, 2 * allocated_, 1024LL}));
  obs_.resize(static_cast<size_t>(n * obs_dim_));
  next_obs_.resize(static_cast<size_t>(n * obs_dim_));
  actions_.resize(static_cast<size_t>(n * act_dim_));
  rewards_.resize(static_cast<size_t>(n));
  terminated_.resize(static_cast<size_t>(n));
  truncated_.resize(static_cast<size_t>(n));
  episode_.resize(static_cast<size_t>(n));
  place_.resize(static_cast<size_t>(n));
  allocated_ = n;
}

long long ReplayBuffer::continuingEpisode() const {
  if (size_ == 0) return 0;
  const long long newest = slotOfAge(0);
  return episode_[newest] + (terminated_[newest] || truncated_[newest] ? 1 : 0);
}

void ReplayBuffer::forgetSlot(long long slot) {
  const auto it = episodes_.find(episode_[slot]);
  MASA_CHECK(it != episodes_.end() && it->second.slots[it->second.first] == slot,
             "replay: slot " << slot << " is not the oldest step of its episode");
  if (++it->second.first == static_cast<long long>(it->second.slots.size())) episodes_.erase(it);
}

void ReplayBuffer::rememberSlot(long long slot) {
  EpisodeSlots& e = episodes_[episode_[slot]];
  place_[slot] = static_cast<long long>(e.slots.size());
  e.slots.push_back(slot);
}

void ReplayBuffer::rebuildEpisodes() {
  episodes_.clear();
  for (long long age = size_ - 1; age >= 0; --age) rememberSlot(slotOfAge(age));
}

long long ReplayBuffer::futureSlot(long long slot, long long window, Rng& rng) const {
  const EpisodeSlots& e = episodes_.at(episode_[slot]);
  const long long at = place_[slot];
  long long last = static_cast<long long>(e.slots.size()) - 1;
  if (window > 0) last = std::min(last, at + window);
  return e.slots[std::uniform_int_distribution<long long>(at, last)(rng)];
}

void ReplayBuffer::add(const float* obs, const float* action, double reward, const float* next_obs, bool terminated,
                       bool truncated, long long episode) {
  MASA_CHECK(episode >= 0 || episode == kContinueStream, "replay: episode ids are >= 0, got " << episode);
  if (episode == kContinueStream) episode = continuingEpisode();
  const long long k = next_;
  reserveSlots(k + 1);
  if (size_ == capacity_) forgetSlot(k);
  std::memcpy(obs_.data() + k * obs_dim_, obs, sizeof(float) * obs_dim_);
  std::memcpy(next_obs_.data() + k * obs_dim_, next_obs, sizeof(float) * obs_dim_);
  std::memcpy(actions_.data() + k * act_dim_, action, sizeof(float) * act_dim_);
  rewards_[k] = static_cast<float>(reward);
  terminated_[k] = terminated;
  truncated_[k] = truncated;
  episode_[k] = episode;
  rememberSlot(k);
  next_ = (next_ + 1) % capacity_;
  size_ = std::min(size_ + 1, capacity_);
  ++added_;
}

long long ReplayBuffer::slotOfAge(long long age) const {
  MASA_CHECK(age >= 0 && age < size_, "no stored step " << age << " steps before the newest (" << size_ << " stored)");
  return ((next_ - 1 - age) % capacity_ + capacity_) % capacity_;
}

template <typename S>
void ReplayBuffer::nStep(long long slot, int n_step, double discount, ReplayBatch<S>& batch, int column,
                         const GoalOverride* goal) const {
  // Steps after `slot` that are stored: up to the newest, never across the write position.
  const long long newer = ((next_ - 1 - slot) % capacity_ + capacity_) % capacity_;
  const long long m_max = std::min<long long>(n_step, newer + 1);
  double ret = 0, g = 1;
  long long k = slot;
  bool terminated = false;
  for (long long j = 0; j < m_max; ++j) {
    k = (slot + j) % capacity_;
    double r = rewards_[k];
    terminated = terminated_[k] != 0;
    if (goal) {
      const task::RelabeledStep step = goal->relabeling->relabel(obsAt(k), nextObsAt(k), r, terminated, goal->goal);
      r = step.reward;
      terminated = step.terminated;
    }
    ret += g * r;
    g *= discount;
    if (terminated || truncated_[k]) break;
  }
  batch.obs.col(column) = Eigen::Map<const Eigen::VectorXf>(obs_.data() + slot * obs_dim_, obs_dim_).cast<S>();
  batch.actions.col(column) = Eigen::Map<const Eigen::VectorXf>(actions_.data() + slot * act_dim_, act_dim_).cast<S>();
  batch.next_obs.col(column) = Eigen::Map<const Eigen::VectorXf>(next_obs_.data() + k * obs_dim_, obs_dim_).cast<S>();
  if (goal) {
    const std::vector<int>& entries = goal->relabeling->goalEntries();
    for (std::size_t i = 0; i < entries.size(); ++i) {
      batch.obs(entries[i], column) = static_cast<S>(goal->goal[i]);
      batch.next_obs(entries[i], column) = static_cast<S>(goal->goal[i]);
    }
  }
  batch.rewards(0, column) = static_cast<S>(ret);
  // A termination (even on the time limit's step) ends the return; a time-out bootstraps.
  batch.discount(0, column) = terminated ? S(0) : static_cast<S>(g);
}

template <typename S>
void ReplayBuffer::sample(int batch_size, int n_step, double discount, Rng& rng, ReplayBatch<S>& batch) const {
  MASA_CHECK(size_ > 0, "cannot sample from an empty replay buffer");
  MASA_CHECK(batch_size > 0 && n_step > 0, "batch size and n must be positive");
  batch.resize(obs_dim_, act_dim_, batch_size);
  // Slots [0, size) are the stored ones whether or not the ring has wrapped.
  std::uniform_int_distribution<long long> pick(0, size_ - 1);
  for (int b = 0; b < batch_size; ++b) nStep(pick(rng), n_step, discount, batch, b);
}

namespace {
// Version 2 adds each stored step's episode; a version 1 buffer's episodes are read as one stream's
// (a new one after each termination or truncation).
constexpr char kMagic[8] = {'M', 'A', 'S', 'A', 'R', 'P', 'L', '2'};
constexpr char kMagicV1[8] = {'M', 'A', 'S', 'A', 'R', 'P', 'L', '1'};

template <typename T>
void writeVector(std::ostream& os, const std::vector<T>& v, long long count) {
  os.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(sizeof(T) * count));
}
template <typename T>
void readVector(std::istream& is, std::vector<T>& v, long long count) {
  is.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(sizeof(T) * count));
}
}  // namespace

void ReplayBuffer::save(std::ostream& os, long long keep_newest) const {
  if (keep_newest >= 0 && keep_newest < size_) {
    // The newest steps as a buffer of their own: slots 0.. in time order, episodes as they are.
    const long long n = keep_newest;
    os.write(kMagic, sizeof kMagic);
    for (long long v : {static_cast<long long>(obs_dim_), static_cast<long long>(act_dim_), capacity_, n, n % capacity_, added_})
      io::writePod(os, v);
    auto write_slots = [&](const auto& v, long long width) {
      for (long long age = n - 1; age >= 0; --age)
        os.write(reinterpret_cast<const char*>(v.data() + slotOfAge(age) * width),
                 static_cast<std::streamsize>(sizeof(v[0]) * width));
    };
    write_slots(obs_, obs_dim_);
    write_slots(next_obs_, obs_dim_);
    write_slots(actions_, act_dim_);
    write_slots(rewards_, 1);
    write_slots(terminated_, 1);
    write_slots(truncated_, 1);
    write_slots(episode_, 1);
    return;
  }
  os.write(kMagic, sizeof kMagic);
  for (long long v : {static_cast<long long>(obs_dim_), static_cast<long long>(act_dim_), capacity_, size_, next_, added_})
    io::writePod(os, v);
  // Only the stored slots: [0, size) holds them whether or not the ring wrapped.
  writeVector(os, obs_, size_ * obs_dim_);
  writeVector(os, next_obs_, size_ * obs_dim_);
  writeVector(os, actions_, size_ * act_dim_);
  writeVector(os, rewards_, size_);
  writeVector(os, terminated_, size_);
  writeVector(os, truncated_, size_);
  writeVector(os, episode_, size_);
}

void ReplayBuffer::load(std::istream& is) {
  char magic[8] = {};
  is.read(magic, sizeof magic);
  const bool v1 = is && std::memcmp(magic, kMagicV1, sizeof kMagicV1) == 0;
  if (!is || (!v1 && std::memcmp(magic, kMagic, sizeof kMagic) != 0))
    throw std::runtime_error("not a masa replay buffer (bad magic)");
  long long h[6];
  for (long long& v : h)
    if (!io::readPod(is, v)) throw std::runtime_error("replay buffer: truncated header");
  if (h[0] != obs_dim_ || h[1] != act_dim_ || h[2] != capacity_)
    throw std::runtime_error("replay buffer holds " + std::to_string(h[0]) + "/" + std::to_string(h[1]) + "/" +
                             std::to_string(h[2]) + " (obs/act/capacity), this one " + std::to_string(obs_dim_) + "/" +
                             std::to_string(act_dim_) + "/" + std::to_string(capacity_));
  if (h[3] < 0 || h[3] > capacity_ || h[4] < 0 || h[4] >= capacity_) throw std::runtime_error("replay buffer: corrupt position");
  reserveSlots(h[3]);
  size_ = h[3];
  next_ = h[4];
  added_ = h[5];
  readVector(is, obs_, size_ * obs_dim_);
  readVector(is, next_obs_, size_ * obs_dim_);
  readVector(is, actions_, size_ * act_dim_);
  readVector(is, rewards_, size_);
  readVector(is, terminated_, size_);
  readVector(is, truncated_, size_);
  if (v1) {
    long long episode = 0;
    for (long long age = size_ - 1; age >= 0; --age) {
      const long long k = slotOfAge(age);
      episode_[k] = episode;
      if (terminated_[k] || truncated_[k]) ++episode;
    }
  } else {
    readVector(is, episode_, size_);
  }
  if (!is) throw std::runtime_error("replay buffer: truncated contents");
  for (long long k = 0; k < size_; ++k)
    if (episode_[k] < 0) throw std::runtime_error("replay buffer: corrupt episode id at slot " + std::to_string(k));
  rebuildEpisodes();
}

template struct ReplayBatch<float>;
template struct ReplayBatch<double>;
template void ReplayBuffer::sample<float>(int, int, double, Rng&, ReplayBatch<float>&) const;
template void ReplayBuffer::sample<double>(int, int, double, Rng&, ReplayBatch<double>&) const;
template void ReplayBuffer::nStep<float>(long long, int, double, ReplayBatch<float>&, int, const GoalOverride*) const;
template void ReplayBuffer::nStep<double>(long long, int, double, ReplayBatch<double>&, int, const GoalOverride*) const;

}  // namespace masa::sac
