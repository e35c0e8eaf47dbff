// An actor's environments as bytes: a header (a tag, the task, the number of environments), then
// per environment its generator (the standard library's text form, exact) and its task's state
// (Task::saveState, doubles). Loading reads everything into scratch first and applies it only when
// the whole file fits, so that a bad file changes nothing.
#include <cstdint>
#include <istream>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "actors/actor.hpp"
#include "common/core/binary_io.hpp"

namespace masa::actor {
namespace {

constexpr std::uint64_t kEnvironmentsTag = 0x3173766e45415341ull;  // "ASAEnvs1", little-endian

void putBytes(std::ostream& out, const std::string& s) {
  io::writePod(out, static_cast<std::uint64_t>(s.size()));
  io::writeArray(out, s.data(), s.size());
}

[[noreturn]] void cutShort(const std::string& what) { throw std::runtime_error("actor environments: cut short in " + what); }

template <class T>
T get(std::istream& in, const char* what) {
  T v{};
  if (!io::readPod(in, v)) cutShort(what);
  return v;
}
std::string getBytes(std::istream& in, std::uint64_t limit, const char* what) {
  const auto n = get<std::uint64_t>(in, what);
  if (n > limit) throw std::runtime_error(std::string("actor environments: ") + what + " of " + std::to_string(n) + " bytes");
  std::string s(n, '\0');
  if (!io::readArray(in, s.data(), n)) cutShort(what);
  return s;
}

}  // namespace

void Actor::saveEnvironments(std::ostream& out) const {
  io::writePod(out, kEnvironmentsTag);
  putBytes(out, config_.task);
  io::writePod(out, static_cast<std::int64_t>(num_envs_));
  std::vector<double> state;
  for (int e = 0; e < num_envs_; ++e) {
    std::ostringstream rng_text;
    rng_text << rngs_[e];
    putBytes(out, rng_text.str());
    state.clear();
    envs_[e]->saveState(state);
    io::writePod(out, static_cast<std::uint64_t>(state.size()));
    io::writeArray(out, state.data(), state.size());
  }
  if (!out) throw std::runtime_error("actor environments: writing failed");
}

void Actor::loadEnvironments(std::istream& in) {
  if (get<std::uint64_t>(in, "the tag") != kEnvironmentsTag)
    throw std::runtime_error("actor environments: not a saved actor's environments (wrong tag)");
  const std::string task = getBytes(in, 256, "the task name");
  if (task != config_.task) throw std::runtime_error("actor environments: of task '" + task + "', this actor runs '" + config_.task + "'");
  const auto n = get<std::int64_t>(in, "the number of environments");
  if (n != num_envs_)
    throw std::runtime_error("actor environments: " + std::to_string(n) + " environments, this actor has " + std::to_string(num_envs_));
  // Everything into scratch first: the generators parsed, the task states loaded into fresh tasks.
  std::vector<Rng> rngs(num_envs_);
  std::vector<std::vector<double>> states(num_envs_);
  for (int e = 0; e < num_envs_; ++e) {
    std::istringstream rng_text(getBytes(in, 1 << 16, "a generator"));
    rng_text >> rngs[e];
    if (!rng_text) throw std::runtime_error("actor environments: environment " + std::to_string(e) + "'s generator is corrupt");
    const auto count = get<std::uint64_t>(in, "a task state's size");
    if (count > (1u << 24)) throw std::runtime_error("actor environments: a task state of " + std::to_string(count) + " values");
    states[e].resize(count);
    if (!io::readArray(in, states[e].data(), count)) cutShort("environment " + std::to_string(e) + "'s task state");
  }
  if (in.peek() != std::char_traits<char>::eof()) throw std::runtime_error("actor environments: bytes after the last environment");
  auto probe = factory_->create();  // each state is checked on a spare task before any is applied
  for (int e = 0; e < num_envs_; ++e) probe->loadState(states[e]);
  for (int e = 0; e < num_envs_; ++e) {
    envs_[e]->loadState(states[e]);
    rngs_[e] = rngs[e];
  }
}

}  // namespace masa::actor
