// The Learner's algorithms behind one interface (issue #54, item 1): the catalog builds each by
// the run's `learner` key; PPO's checkpoint body carries everything its next update needs; a
// version 1 checkpoint (lr before the rng state, a PPO body in every run) still reads.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <sstream>
#include <string>

#include "common/config/run_config.hpp"
#include "common/core/binary_io.hpp"
#include "common/integrity/sealed_file.hpp"
#include "learner/algorithms/algorithm_catalog.hpp"
#include "learner/run_dir/checkpoint.hpp"
#include "learner/ppo_algorithm.hpp"

namespace masa {
namespace {

namespace fs = std::filesystem;

config::RunConfig algorithmTestConfig(const std::string& learner) {
  return config::loadRunConfig(config::defaultConfigsDir(),
                               {"task=a1_beam", "method=masa", "learner=" + learner, "model.policy_hidden=[16]",
                                "model.critic_hidden=[16]", "sac.policy_hidden=[16]", "sac.q_hidden=[16]"});
}

TEST(LearnerAlgorithm, TheCatalogBuildsEachByItsLearnerKey) {
  Rng rng(1);
  EXPECT_EQ(learner::makeAlgorithm(algorithmTestConfig("ppo"), rng, cluster::soloCommunicator())->kind(), "ppo");
  const auto off = learner::makeAlgorithm(algorithmTestConfig("off_policy"), rng, cluster::soloCommunicator());
  EXPECT_EQ(off->kind(), "off_policy");
  ASSERT_TRUE(off->sideState().has_value());
  EXPECT_EQ(off->sideState()->name, "off_policy_state.bin");
  EXPECT_EQ(off->roundTable(), "off_policy.csv");
  EXPECT_FALSE(off->dataParallel());
  // A program that runs PPO alone refuses the other key by name.
  try {
    learner::makePpoAlgorithm(algorithmTestConfig("off_policy"), rng, cluster::soloCommunicator());
    FAIL() << "PPO's factory built an off-policy run";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("off_policy is not built into this program"), std::string::npos) << e.what();
  }
}

TEST(LearnerAlgorithm, PpoCheckpointBodyRestoresWhatEveryRankMustHoldAlike) {
  const auto rc = algorithmTestConfig("ppo");
  Rng a_rng(5), b_rng(6);
  learner::PpoAlgorithm a(rc, a_rng, cluster::soloCommunicator()), b(rc, b_rng, cluster::soloCommunicator());
  ASSERT_NE(a.agreementHash(), b.agreementHash()) << "two seeds gave the same networks";
  std::stringstream body;
  a.saveCheckpointBody(body);
  b.loadCheckpointBody(body, "body");
  EXPECT_EQ(a.agreementHash(), b.agreementHash());
  // A body with a byte too many is refused.
  std::stringstream longer(body.str() + "x");
  EXPECT_THROW(b.loadCheckpointBody(longer, "longer"), std::runtime_error);
}

TEST(LearnerAlgorithm, AVersionOneCheckpointReadsAsALegacyPpoBody) {
  const auto rc = algorithmTestConfig("ppo");
  Rng rng(7);
  learner::PpoAlgorithm written(rc, rng, cluster::soloCommunicator());
  std::stringstream body;
  written.saveCheckpointBody(body);  // lr, shuffle, model, Adam: version 1 had lr ahead of the rng state
  const std::string b = body.str();
  double lr = 0;
  std::memcpy(&lr, b.data(), sizeof lr);
  std::ostringstream v1(std::ios::binary);
  v1.write("MASACKP1", 8);
  for (int64_t v : {int64_t{42}, int64_t{3}, int64_t{3}, int64_t{96}}) io::writePod(v1, v);
  io::writePod(v1, 12.5);
  io::writePod(v1, lr);
  const std::string rng_text = "1 2 3";
  io::writePod(v1, static_cast<uint64_t>(rng_text.size()));
  v1.write(rng_text.data(), static_cast<std::streamsize>(rng_text.size()));
  v1.write(b.data() + sizeof lr, static_cast<std::streamsize>(b.size() - sizeof lr));
  const fs::path path = fs::temp_directory_path() / ("masa_v1_checkpoint_" + std::to_string(::getpid()) + ".bin");
  integrity::writeSealedFile(path.string(), learner::kCheckpointFileKind, v1.view());
  const learner::CheckpointState s = learner::readCheckpoint(path.string());
  fs::remove(path);
  EXPECT_TRUE(s.legacy);
  EXPECT_EQ(s.kind, "ppo");
  EXPECT_EQ(s.run_id, 42);
  EXPECT_EQ(s.updates, 3);
  EXPECT_EQ(s.env_steps, 96);
  EXPECT_EQ(s.rng_state, rng_text);
  EXPECT_EQ(s.body, b);
  Rng other(8);
  learner::PpoAlgorithm read(rc, other, cluster::soloCommunicator());
  std::istringstream is(s.body);
  read.loadCheckpointBody(is, path.string());
  EXPECT_EQ(read.agreementHash(), written.agreementHash());
}

TEST(LearnerAlgorithm, AVersionTwoCheckpointKeepsItsAlgorithmKind) {
  learner::CheckpointState s;
  s.run_id = 9;
  s.updates = s.version = 2;
  s.rng_state = "4 5";
  s.kind = "off_policy";
  const fs::path path = fs::temp_directory_path() / ("masa_v2_checkpoint_" + std::to_string(::getpid()) + ".bin");
  learner::writeCheckpoint(path.string(), s);
  const learner::CheckpointState back = learner::readCheckpoint(path.string());
  fs::remove(path);
  EXPECT_FALSE(back.legacy);
  EXPECT_EQ(back.kind, "off_policy");
  EXPECT_EQ(back.body, "");
  EXPECT_EQ(back.rng_state, "4 5");
}

}  // namespace
}  // namespace masa
