// A receiver that restarts must not take a sender's recorded history again (issue #55, item 3):
// its counter windows start empty, and before, an empty window took any counter, so every
// message recorded before the restart was taken once more, in order. A counter is the sender's
// clock when it signed (message_sign.hpp), and a receiver refuses what was signed before it
// started (before_start), for the training channels and the robot's alike.
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "common/integrity/ed25519_keys.hpp"
#include "common/transport/channels.hpp"
#include "common/transport/message_sign.hpp"
#include "common/transport/roster.hpp"
#include "common/transport/transport.hpp"
#include "masa/lcmt_robot_command.hpp"

namespace masa::transport {
namespace {

namespace fs = std::filesystem;

// A roster of runner 0 and robot 0 in a temporary directory, and the runner's signer.
struct RobotKeys {
  fs::path dir = fs::temp_directory_path() / ("masa_test_restart_" + std::to_string(::getpid()));
  std::shared_ptr<Roster> roster = std::make_shared<Roster>();
  std::shared_ptr<MessageSigner> runner;
  RobotKeys() {
    fs::remove_all(dir);
    fs::create_directories(dir);
    for (Role role : {Role::kRunner, Role::kRobot}) {
      const std::string stem = (dir / std::string(roleName(role))).string();
      roster->add({role, 0}, integrity::generateKeyPair(stem + ".key", stem + ".pub"), defaultChannels(role));
    }
    runner = MessageSigner::load((dir / "runner.key").string(), {Role::kRunner, 0}, *roster);
  }
  ~RobotKeys() { fs::remove_all(dir); }
};

std::vector<uint8_t> signedCommand(MessageSigner& signer, int64_t utime) {
  masa::lcmt_robot_command cmd{};
  cmd.num_joints = 1;
  cmd.position = cmd.velocity = cmd.torque_ff = cmd.kp = cmd.kd = {0.0};
  cmd.utime = utime;
  std::vector<uint8_t> out(static_cast<std::size_t>(cmd.getEncodedSize()) + kSigTrailerBytes);
  cmd.encode(out.data(), 0, cmd.getEncodedSize());
  signer.seal(kRobotCommandChannel, out.data(), cmd.getEncodedSize(), out.data() + cmd.getEncodedSize());
  return out;
}

// A robot side that verifies (masa_sim_robot's): how many commands reached it.
struct VerifyingRobot {
  Transport bus;
  int taken = 0;
  explicit VerifyingRobot(std::shared_ptr<const Roster> roster) : bus("memq://", SignedMode{nullptr, std::move(roster), {}}) {
    bus.subscribeRaw(kRobotCommandChannel, [this](const void*, int) { ++taken; });
  }
  void send(const std::vector<uint8_t>& b) {
    ASSERT_TRUE(bus.publishWire(kRobotCommandChannel, b.data(), static_cast<int>(b.size())));
    for (int i = 0; i < 3; ++i) bus.handleTimeout(5);
  }
};

TEST(ReplayAfterRestart, TheRunnersCommandsRecordedBeforeTheRobotRestartedAreRefusedAsBeforeStart) {
  RobotKeys keys;
  std::vector<std::vector<uint8_t>> recorded;
  {
    VerifyingRobot first_life(keys.roster);
    for (int k = 0; k < 5; ++k) {
      recorded.push_back(signedCommand(*keys.runner, 1000 + k));
      first_life.send(recorded.back());
    }
    ASSERT_EQ(first_life.taken, 5);
    first_life.send(recorded.front());
    EXPECT_EQ(first_life.taken, 5) << "a replay within one life";
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(2));
  VerifyingRobot second_life(keys.roster);
  for (const auto& b : recorded) second_life.send(b);  // the history, in order, after the restart
  EXPECT_EQ(second_life.taken, 0) << "a command recorded before the restart was taken: " << second_life.bus.rejectSummary();
  EXPECT_NE(second_life.bus.rejectSummary().find("before_start 5"), std::string::npos) << second_life.bus.rejectSummary();
  // The runner's next command, signed after the restart, is taken.
  second_life.send(signedCommand(*keys.runner, 2000));
  EXPECT_EQ(second_life.taken, 1) << second_life.bus.rejectSummary();
}

TEST(ReplayAfterRestart, CountersFollowTheClockSoASenderStartedLongBeforeTheReceiverIsTaken) {
  // A sender that started long before the receiver and sent little: its counters are its clock,
  // not its start time plus its message count, so its new messages are above the receiver's start.
  RobotKeys keys;
  auto early = std::make_shared<MessageSigner>(integrity::SigningKey::load((keys.dir / "runner.key").string()),
                                               SenderId{Role::kRunner, 0}, 1);
  std::this_thread::sleep_for(std::chrono::milliseconds(2));
  VerifyingRobot robot(keys.roster);
  robot.send(signedCommand(*early, 1));
  EXPECT_EQ(robot.taken, 1) << robot.bus.rejectSummary();
}

}  // namespace
}  // namespace masa::transport
