// A task's saved state (Task::saveState / loadState) is the whole state: an instance that loads it
// in the middle of an episode goes on exactly as the one that saved it, bit for bit (observations,
// rewards, terminations, episode statistics), for every shipped task and the YAML tasks. A state of
// another task, cut short, or with a count that does not add up is refused, naming what is wrong.
// (Two ways loading went wrong before, caught here: mj_forward after loading normalized the free
// joints' quaternions again, off by a bit in humanoid_dribbling's ball, and left its own solution
// in the warm start, which moved A1 Beam's and TriFinger's next steps by 1e-17 to 1e-13.)
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "task_test_support.hpp"

namespace masa::task {
namespace {

using namespace masa::test;

// Everything an actor reads from a task after a step, as bits.
struct Trace {
  std::vector<float> obs;
  std::vector<double> numbers;
  void record(const Task& t, const StepOutcome& out) {
    const auto o = observation(t);
    obs.insert(obs.end(), o.begin(), o.end());
    numbers.insert(numbers.end(), {out.reward, double(out.terminated), double(out.truncated), t.episode().ret,
                                   double(t.episode().length), double(t.episode().success)});
    numbers.insert(numbers.end(), t.episode().term_sums.begin(), t.episode().term_sums.end());
  }
};

// Steps with random actions from `rng`, resetting at the ends of episodes from `reset_rng`.
Trace driveTask(Task& t, Rng& rng, Rng& reset_rng, int steps) {
  Trace trace;
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> a(t.actDim());
  for (int s = 0; s < steps; ++s) {
    for (float& x : a) x = u(rng);
    const StepOutcome out = t.step(a.data());
    trace.record(t, out);
    if (out.terminated || out.truncated) t.reset(reset_rng);
  }
  return trace;
}

// Where saveState puts the count of the task's extras (the layout of common/sim/task_state.cpp).
std::size_t extrasCountIndex(const Task& t) {
  const mjModel* m = t.model();
  const std::size_t nterms = t.rewardTermNames().size();
  return 10 + 1 + m->nq + 3 * std::size_t(m->nv) + m->na + m->nu + 6 * std::size_t(m->nbody) + 7 * std::size_t(m->nmocap) +
         m->nuserdata + t.actDim() + 6 + 2 * nterms;
}

class TaskState : public ::testing::TestWithParam<std::string> {};

TEST_P(TaskState, AnInstanceThatLoadsTheStateGoesOnAsTheOneThatSavedIt) {
  const TaskFactory f = runConfigFactory(GetParam(), {"env.max_episode_steps=30"});
  auto a = f.create(), b = f.create();
  Rng reset_a(11), act_a(12);
  a->reset(reset_a);
  driveTask(*a, act_a, reset_a, 40);  // past one time limit: an episode under way, not a fresh one
  ASSERT_GT(a->episode().length, 0);

  std::vector<double> state;
  a->saveState(state);
  Rng reset_b = reset_a, act_b = act_a;
  Rng other(99);
  b->reset(other);
  driveTask(*b, other, other, 7);  // b is somewhere else entirely before it loads
  b->loadState(state);
  EXPECT_EQ(observation(*b), observation(*a)) << "the observation right after loading";

  const Trace ta = driveTask(*a, act_a, reset_a, 45), tb = driveTask(*b, act_b, reset_b, 45);
  ASSERT_EQ(ta.obs.size(), tb.obs.size());
  EXPECT_EQ(0, std::memcmp(ta.obs.data(), tb.obs.data(), ta.obs.size() * sizeof(float))) << "observations differ";
  ASSERT_EQ(ta.numbers.size(), tb.numbers.size());
  EXPECT_EQ(0, std::memcmp(ta.numbers.data(), tb.numbers.data(), ta.numbers.size() * sizeof(double)))
      << "rewards or episode statistics differ";
  // And the state saved again is the state, value for value.
  std::vector<double> again_a, again_b;
  a->saveState(again_a);
  b->saveState(again_b);
  EXPECT_EQ(again_a, again_b);
}

INSTANTIATE_TEST_SUITE_P(EveryTask, TaskState,
                         ::testing::Values("a1_beam", "ant_acrobatic", "trifinger_lift", "humanoid_tightrope",
                                           "humanoid_dribbling", "a1_beam_yaml", "ant_acrobatic_yaml"));

// Why loadState refused `state` ("" when it took it).
std::string stateRefusal(Task& t, const std::vector<double>& state) {
  try {
    t.loadState(state);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(TaskStateRefused, AnotherTaskCutShortOrAWrongExtrasCountIsRefusedByName) {
  auto ant = runConfigFactory("ant_acrobatic").create();
  auto a1 = runConfigFactory("a1_beam").create();
  Rng rng(3);
  ant->reset(rng);
  a1->reset(rng);
  std::vector<double> state;
  ant->saveState(state);
  auto expectRefused = [](Task& t, const std::vector<double>& s, const std::string& why) {
    const std::string said = stateRefusal(t, s);
    EXPECT_NE(said.find(why), std::string::npos) << "expected a refusal saying '" << why << "', got '" << said << "'";
  };
  expectRefused(*a1, state, "task state of a1_beam: nq is 29");  // another task's
  auto ant2 = runConfigFactory("ant_acrobatic").create();
  expectRefused(*ant2, std::vector<double>(state.begin(), state.begin() + 40), "is cut short");
  std::vector<double> longer = state;
  longer.push_back(1.0);  // one value after the extras that their count does not cover
  expectRefused(*ant2, longer, "after the count of the task's extras");
  // A task's own check of its extras: a dribbling route one value short, the count made to match.
  auto drib = runConfigFactory("humanoid_dribbling").create();
  drib->reset(rng);
  std::vector<double> d;
  drib->saveState(d);
  const std::size_t count_at = extrasCountIndex(*drib);
  ASSERT_EQ(d[count_at], double(d.size() - count_at - 1));
  d.pop_back();
  d[count_at] -= 1.0;
  expectRefused(*drib, d, "humanoid_dribbling state:");
}

}  // namespace
}  // namespace masa::task
