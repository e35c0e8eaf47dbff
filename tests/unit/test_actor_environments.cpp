// An actor's environments saved between rollouts and loaded into another actor of the same run:
// the loaded actor's next rollout is the saver's, bit for bit; a file that does not fit (cut short
// anywhere, another task, another number of environments, a foreign tag, bytes after the end) is
// refused by name and changes nothing. The file they are written to (actor_state.bin) is sealed:
// a bit flipped at any byte, or random damage of any kind, is refused and changes nothing.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "actors/actor.hpp"
#include "actors/environments_snapshot.hpp"
#include "common/config/run_config.hpp"
#include "common/symmetry/symmetry_spec.hpp"
#include "common/transport/channels.hpp"
#include "common/transport/transport.hpp"
#include "file_mutations.hpp"
#include "masa/lcmt_policy_params.hpp"

namespace masa {
namespace {

constexpr int64_t kRunId = 99;

config::RunConfig smallConfig(const std::string& task) {
  return config::loadRunConfig(std::string(MASA_SOURCE_DIR) + "/configs",
                               {"task=" + task, "seed=3", "ppo.horizon=6", "model.policy_hidden=[8]",
                                "model.critic_hidden=[8]", "env.max_episode_steps=4"});
}

actor::ActorOptions options(int num_envs) {
  actor::ActorOptions o;
  o.num_envs = num_envs;
  o.run_id = kRunId;
  o.threads = 1;
  o.incarnation = 1;
  o.await_params_s = 0;
  return o;
}

// The whole policy of a freshly initialized model of the config, as the learner broadcasts it.
masa::lcmt_policy_params paramsFor(const config::RunConfig& rc) {
  const auto spec = sym::SymmetrySpec::load(rc.spec_path);
  model::ActorCritic<float> model(spec, rc.model);
  Rng rng(5);
  model.initialize(rng);
  masa::lcmt_policy_params p;
  p.run_id = kRunId;
  p.version = 1;
  p.method = model::methodName(rc.method);
  p.task = rc.task;
  p.num_params = model.params().size();
  p.params.assign(model.params().values().data(), model.params().values().data() + p.num_params);
  p.obs_dim = spec.obsDim();
  p.obs_mean.assign(p.obs_dim, 0.0f);
  p.obs_std.assign(p.obs_dim, 1.0f);
  return p;
}

// One actor on its own in-process bus, given the parameters.
struct ActorUnderTest {
  ActorUnderTest(const config::RunConfig& rc, int num_envs) : bus("memq://"), actor(rc, options(num_envs), &bus) {
    EXPECT_TRUE(bus.publish(transport::kPolicyChannel, paramsFor(rc)));
    EXPECT_TRUE(actor.pollParams(100));
  }
  std::vector<float> nextObservations() {
    EXPECT_TRUE(actor.collectAndPublish());
    return actor.lastRollout().obs;
  }
  std::string saved() const {
    std::ostringstream out;
    actor.saveEnvironments(out);
    return out.str();
  }
  transport::Transport bus;
  actor::Actor actor;
};

std::string loadError(actor::Actor& actor, const std::string& bytes) {
  std::istringstream in(bytes);
  try {
    actor.loadEnvironments(in);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(ActorEnvironments, AnActorThatLoadsThemCollectsTheSaversNextRollout) {
  const auto rc = smallConfig("a1_beam");
  ActorUnderTest saver(rc, 3), loader(rc, 3);
  saver.nextObservations();  // mid-episode: 6 steps of 4-step episodes
  const std::string bytes = saver.saved();
  ASSERT_EQ(loadError(loader.actor, bytes), "");
  const auto expected = saver.nextObservations();
  EXPECT_EQ(loader.nextObservations(), expected);
  EXPECT_EQ(loader.nextObservations(), saver.nextObservations()) << "and the one after";
}

TEST(ActorEnvironments, AFileThatDoesNotFitIsRefusedByNameAndChangesNothing) {
  const auto rc = smallConfig("a1_beam");
  ActorUnderTest saver(rc, 2), loader(rc, 2), untouched(rc, 2);
  saver.nextObservations();
  const std::string bytes = saver.saved();

  // Cut short anywhere: in the header, a generator or a task state.
  for (std::size_t n : {std::size_t{0}, std::size_t{5}, std::size_t{20}, bytes.size() / 3, bytes.size() / 2, bytes.size() - 1}) {
    const std::string why = loadError(loader.actor, bytes.substr(0, n));
    EXPECT_NE(why.find("cut short"), std::string::npos) << n << " bytes: " << why;
  }
  EXPECT_NE(loadError(loader.actor, bytes + "x").find("bytes after the last environment"), std::string::npos);
  std::string foreign = bytes;
  foreign[0] ^= 0x40;
  EXPECT_NE(loadError(loader.actor, foreign).find("wrong tag"), std::string::npos);

  ActorUnderTest other_count(rc, 3);
  other_count.nextObservations();
  EXPECT_NE(loadError(loader.actor, other_count.saved()).find("3 environments, this actor has 2"), std::string::npos);
  ActorUnderTest other_task(smallConfig("ant_acrobatic"), 2);
  other_task.nextObservations();
  EXPECT_NE(loadError(loader.actor, other_task.saved()).find("of task 'ant_acrobatic', this actor runs 'a1_beam'"),
            std::string::npos);

  EXPECT_EQ(loader.nextObservations(), untouched.nextObservations()) << "a refused file changed the environments";
}

std::string slurp(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void spit(const std::string& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::string resumeError(const std::string& path, actor::Actor& actor) {
  try {
    return actor::resumeEnvironments(path, 1, actor);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
}

TEST(ActorEnvironmentsFile, ABitFlippedAtAnyByteOrRandomDamageIsRefusedAndChangesNothing) {
  const auto rc = smallConfig("a1_beam");
  ActorUnderTest saver(rc, 2), loader(rc, 2), untouched(rc, 2);
  saver.nextObservations();
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("masa_actor_state_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string good = (dir / "actor_state.bin").string(), bad = (dir / "damaged.bin").string();
  actor::EnvironmentsSnapshot snapshot;
  snapshot.take(saver.actor, 1);
  snapshot.writeIfAt(1, good);
  const std::string bytes = slurp(good);
  spit(bad, bytes);
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    fuzz::flipBitInFile(bad, i);
    const std::string why = resumeError(bad, loader.actor);
    ASSERT_EQ(why.rfind(bad + ": ", 0), 0u) << "byte " << i << " of " << bytes.size() << " flipped: '" << why << "'";
    fuzz::flipBitInFile(bad, i);
  }
  std::mt19937_64 rng(36);
  for (int i = 0; i < 300; ++i) {
    const fuzz::FileMutation mut = fuzz::mutateFile(bytes, rng);
    if (mut.bytes == bytes) continue;
    spit(bad, mut.bytes);
    ASSERT_NE(resumeError(bad, loader.actor), "") << "mutation " << i << " (" << mut.what << ") was accepted";
  }
  EXPECT_EQ(loader.nextObservations(), untouched.nextObservations()) << "a refused file changed the environments";
  // A file from before the seal (the seal's content alone) resumes, with a warning naming it.
  const std::string old = (dir / "old_actor_state.bin").string();
  spit(old, bytes.substr(52 + 4 + actor::kEnvironmentsFileKind.name.size()));
  ActorUnderTest old_loader(rc, 2);
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(resumeError(old, old_loader.actor), "");
  EXPECT_NE(::testing::internal::GetCapturedStderr().find("warning: " + old + ": written before masa sealed its files"), std::string::npos);
  ASSERT_EQ(resumeError(good, loader.actor), "");
  EXPECT_EQ(loader.nextObservations(), saver.nextObservations()) << "the intact file resumes exactly";
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace masa
