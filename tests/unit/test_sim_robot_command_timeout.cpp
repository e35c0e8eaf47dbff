// masa_sim_robot's own safe state when commands stop (deploy/sim_robot/command_timeout.hpp, issue
// #55 item 2), on a simulated clock: the newest command while commands arrive, the robot's own
// damping once none arrived for the timeout, the quiet runner not followed again, a new runner
// taking over. Over real LCM with a killed runner: deploy_sim_robot.sh command_timeout.
#include <gtest/gtest.h>

#include "deploy/sim_robot/command_timeout.hpp"

namespace masa::deploy {
namespace {

masa::lcmt_robot_command runnerCommand(int64_t runner_id, int64_t utime) {
  masa::lcmt_robot_command c{};
  c.num_joints = 2;
  c.position = {0.3, -0.3};
  c.velocity = {0.0, 0.0};
  c.torque_ff = {0.0, 0.0};
  c.kp = {40.0, 40.0};
  c.kd = {1.0, 1.0};
  c.runner_id = runner_id;
  c.utime = utime;
  c.mode = 1;
  return c;
}

bool isOwnDamping(const masa::lcmt_robot_command& c, double kd) {
  for (int k = 0; k < c.num_joints; ++k)
    if (c.kp[k] != 0.0 || c.kd[k] != kd || c.velocity[k] != 0.0 || c.torque_ff[k] != 0.0) return false;
  return c.mode == 2;
}

TEST(SimRobotCommandTimeout, DampsOnceCommandsStopAndFollowsOnlyANewRunner) {
  CommandTimeout timeout(0.15, 2.0, 2);
  masa::lcmt_robot_command newest = runnerCommand(7, 1);
  // 50 Hz commands for a second: each is applied.
  double last = 0;
  for (int i = 0; i < 50; ++i) {
    last = 0.02 * i;
    newest = runnerCommand(7, i + 1);
    timeout.arrived(newest, last);
    EXPECT_EQ(&timeout.commandFor(newest, last + 0.005), &newest);
  }
  // Silence: the last command holds up to the bound, then the robot's own damping.
  EXPECT_EQ(&timeout.commandFor(newest, last + 0.149), &newest);
  EXPECT_LT(timeout.firstSilenceS(), 0);
  const masa::lcmt_robot_command& applied = timeout.commandFor(newest, last + 0.155);
  EXPECT_TRUE(isOwnDamping(applied, 2.0));
  EXPECT_NEAR(timeout.firstSilenceS(), 0.155, 1e-9);
  EXPECT_EQ(timeout.firstQuietRunner(), 7);
  // The quiet runner comes back: ignored, counted; the robot stays damped.
  const masa::lcmt_robot_command late = runnerCommand(7, 100);
  timeout.arrived(late, last + 0.3);
  EXPECT_TRUE(isOwnDamping(timeout.commandFor(late, last + 0.3), 2.0));
  EXPECT_EQ(timeout.ignoredCommands(), 1);
  // A new runner takes over, and its silence is timed in turn.
  const masa::lcmt_robot_command fresh = runnerCommand(8, 200);
  timeout.arrived(fresh, last + 1.0);
  EXPECT_EQ(&timeout.commandFor(fresh, last + 1.01), &fresh);
  EXPECT_TRUE(isOwnDamping(timeout.commandFor(fresh, last + 1.2), 2.0));
  EXPECT_EQ(timeout.firstQuietRunner(), 7) << "the first trip is what the report names";
}

TEST(SimRobotCommandTimeout, NoCommandYetOrNoTimeoutKeepsTheNewest) {
  const masa::lcmt_robot_command newest = runnerCommand(7, 1);
  CommandTimeout before_any(0.15, 2.0, 2);
  EXPECT_EQ(&before_any.commandFor(newest, 100.0), &newest);  // the robot hangs still until a first command
  CommandTimeout never(0.0, 2.0, 2);
  never.arrived(newest, 0.0);
  EXPECT_EQ(&never.commandFor(newest, 100.0), &newest);
  EXPECT_LT(never.firstSilenceS(), 0);
}

}  // namespace
}  // namespace masa::deploy
