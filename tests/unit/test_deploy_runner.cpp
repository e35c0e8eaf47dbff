// masa_deploy's runner logic (deploy/runner/policy_runner.hpp) on a simulated clock, with the A1
// Beam policy we ship: the observation is the task's own, the watchdog answers stale and
// non-finite state within its bound, every command keeps the limits (also for random policies),
// the calibration ramp keeps its rate, and the control step allocates nothing. The same runner
// against the simulated robot over real LCM: tests/integration/deploy_*.sh.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "alloc_counter.hpp"
#include "common/transport/message_mutator.hpp"
#include "common/transport/wire_guard.hpp"
#include "common/core/config_error.hpp"
#include "common/policy/policy_file.hpp"
#include "deploy/runner/deploy_config.hpp"
#include "deploy/runner/policy_runner.hpp"
#include "deploy/runner/realtime.hpp"
#include "robot_state_message.hpp"
#include "tasks/tasks.hpp"

namespace masa::deploy {
namespace {

using test::stateOf;

const std::string kPolicy = std::string(MASA_SOURCE_DIR) + "/tasks/a1_beam/policy/policy.bin";

struct RunnerFixture {
  policy::LoadedPolicy lp = policy::loadPolicyFile(kPolicy);
  task::TaskFactory factory{task::taskCatalog(), lp.config.task, lp.spec, lp.config.env, lp.config.origin, lp.source};
  std::unique_ptr<task::Task> sim = factory.create();
  RunnerFixture() {
    Rng rng(0);
    sim->reset(rng);
  }
};

DeployConfig testConfig() {
  DeployConfig c = loadDeployConfig("");
  c.calibration_settle_s = 0.1;
  return c;
}

// Drives a runner with a state every `state_us` from the (still) simulated robot until `until_us`,
// polling every 100 us; returns the commands with their times.
struct Sent {
  int64_t t;
  masa::lcmt_robot_command c;
};
std::vector<Sent> drive(PolicyRunner& r, task::Task& sim, int64_t from_us, int64_t until_us, int64_t state_us,
                        int64_t& utime) {
  std::vector<Sent> out;
  masa::lcmt_robot_command cmd = r.makeCommand();
  for (int64_t t = from_us; t < until_us; t += 100) {
    if (state_us > 0 && (t - from_us) % state_us == 0) r.onState(stateOf(sim, ++utime), t);
    if (r.poll(t, cmd)) out.push_back({t, cmd});
  }
  return out;
}

TEST(DeployRunner, ObservationFromAStateMessageEqualsTheTasksOwnInSimulation) {
  RunnerFixture f;
  std::unique_ptr<task::Task> robot_side = f.factory.create();  // never reset, never stepped
  Rng rng(3);
  std::normal_distribution<float> noise(0.0f, 0.5f);
  std::vector<float> a(f.sim->actDim()), want(f.sim->obsDim()), got(f.sim->obsDim());
  for (int t = 0; t < 20; ++t) {
    for (float& x : a) x = noise(rng);
    f.sim->step(a.data());
    f.sim->observe(want.data());
    const masa::lcmt_robot_state s = stateOf(*f.sim, t + 1);
    const double base[13] = {s.base_x,  s.base_y,  s.base_z,  s.base_qw, s.base_qx, s.base_qy, s.base_qz,
                             s.base_vx, s.base_vy, s.base_vz, s.base_wx, s.base_wy, s.base_wz};
    robot_side->setMeasuredState(s.joint_position.data(), s.joint_velocity.data(), base, base + 7,
                                 f.sim->lastAction().data());
    robot_side->observe(got.data());
    for (int i = 0; i < f.sim->obsDim(); ++i) ASSERT_EQ(got[i], want[i]) << "observation entry " << i << " at step " << t;
  }
}

// The runner freezes the policy it runs (its weights are packed once for the agent columns) and
// acts with the bits of the same policy unfrozen, as the actors and the evaluation run it.
TEST(DeployRunner, FreezesItsPolicyAndActsWithTheBitsOfTheUnfrozenPolicy) {
  RunnerFixture f;
  PolicyRunner r(f.lp, testConfig(), 1);
  EXPECT_THROW(r.policy().params().values(), std::exception);
  EXPECT_EQ(r.policy().params().size(), f.lp.model->policyParamCount()) << "the policy half only: no critic on the robot";
  policy::LoadedPolicy unfrozen = policy::loadPolicyFile(kPolicy);
  Rng rng(5);
  std::normal_distribution<float> noise(0.0f, 1.0f);
  Mat<float> obs(f.lp.model->obsDim(), 1);
  for (int t = 0; t < 10; ++t) {
    for (float& x : obs.reshaped()) x = noise(rng);
    const Mat<float> frozen_mean = r.policy().actMean(obs);
    EXPECT_TRUE(frozen_mean == unfrozen.model->actMean(obs)) << "observation " << t;
  }
}

// The humanoid is torque-controlled: its joint command is the motor torque the task applies for
// the same action (gains zero), and its observation from a state message is the task's own.
TEST(DeployRunner, HumanoidJointCommandIsTheTasksMotorTorqueAndItsObservationTheTasksOwn) {
  policy::LoadedPolicy lp =
      policy::loadPolicyFile(std::string(MASA_SOURCE_DIR) + "/tasks/humanoid_tightrope/policy/policy.bin");
  task::TaskFactory factory{task::taskCatalog(), lp.config.task, lp.spec, lp.config.env, lp.config.origin, lp.source};
  std::unique_ptr<task::Task> sim = factory.create(), robot_side = factory.create();
  Rng rng(5);
  sim->reset(rng);
  const int n = sim->actDim();
  const mjModel* m = sim->model();
  std::normal_distribution<float> noise(0.0f, 0.7f);
  std::vector<float> a(n), want(sim->obsDim()), got(sim->obsDim());
  std::vector<double> action(n), pos(n), vel(n), tau(n), kp(n), kd(n), q(n), qd(n);
  for (int t = 0; t < 10; ++t) {
    for (int k = 0; k < n; ++k) action[k] = a[k] = noise(rng);
    ASSERT_TRUE(sim->jointCommand(action.data(), pos.data(), vel.data(), tau.data(), kp.data(), kd.data()));
    sim->actuate(a.data());
    for (int k = 0; k < n; ++k) {
      const int act = sim->actuatorOfAction(k);
      EXPECT_NEAR(tau[k], sim->data()->ctrl[act] * m->actuator_gear[6 * act], 1e-12) << "action " << k;
      EXPECT_EQ(kp[k], 0.0);
      EXPECT_EQ(kd[k], 0.0);
    }
    sim->step(a.data());
    sim->observe(want.data());
    const int root = mj_name2id(m, mjOBJ_JOINT, "root");
    for (int k = 0; k < n; ++k) {
      const int j = sim->jointOfAction(k);
      q[k] = sim->data()->qpos[m->jnt_qposadr[j]];
      qd[k] = sim->data()->qvel[m->jnt_dofadr[j]];
    }
    robot_side->setMeasuredState(q.data(), qd.data(), sim->data()->qpos + m->jnt_qposadr[root],
                                 sim->data()->qvel + m->jnt_dofadr[root], sim->lastAction().data());
    robot_side->observe(got.data());
    for (int i = 0; i < sim->obsDim(); ++i) ASSERT_EQ(got[i], want[i]) << "observation entry " << i << " at step " << t;
  }
}

TEST(DeployRunner, StaleStateGivesTheSafeCommandWithinTheBoundAndSaysWhy) {
  RunnerFixture f;
  PolicyRunner r(f.lp, testConfig(), 1);
  int64_t utime = 0;
  // 2 s of state at 200 Hz: calibration, then the policy.
  auto sent = drive(r, *f.sim, 0, 2000000, 5000, utime);
  ASSERT_FALSE(sent.empty());
  for (const Sent& s : sent) ASSERT_LT(s.c.mode, 2) << "safe command while the state was fresh, at " << s.t;
  EXPECT_EQ(sent.back().c.mode, static_cast<int>(Mode::kPolicy));
  const int64_t last_state = 1995000;
  // The state stops.
  sent = drive(r, *f.sim, 2000000, 2500000, 0, utime);
  const auto safe = std::find_if(sent.begin(), sent.end(), [](const Sent& s) { return s.c.mode >= 2; });
  ASSERT_NE(safe, sent.end()) << "no safe command after the state stopped";
  EXPECT_EQ(safe->c.mode, static_cast<int>(Mode::kDamping));
  EXPECT_LE(safe->t - last_state, static_cast<int64_t>(r.watchdogBoundS() * 1e6));
  for (int k = 0; k < r.numJoints(); ++k) EXPECT_EQ(safe->c.kp[k], 0.0);
  EXPECT_NE(r.reason().find("no new state"), std::string::npos) << r.reason();
  // Latched: it keeps sending the safe command, one per period, even when state comes back.
  sent = drive(r, *f.sim, 2500000, 2700000, 5000, utime);
  ASSERT_GE(sent.size(), 5u);
  for (const Sent& s : sent) EXPECT_EQ(s.c.mode, static_cast<int>(Mode::kDamping));
}

// Issue #55: an ending (a signal, another runner, an error) puts the configured safe command on the
// wire at once, not at the next due time; already latched, the latched command goes out at once.
TEST(DeployRunner, StopNowGivesTheConfiguredSafeCommandAtOnce) {
  RunnerFixture f;
  for (const SafeMode safe : {SafeMode::kDamping, SafeMode::kHold}) {
    DeployConfig cfg = testConfig();
    cfg.safe_mode = safe;
    PolicyRunner r(f.lp, cfg, 1);
    int64_t utime = 0;
    auto sent = drive(r, *f.sim, 0, 1000000, 5000, utime);
    ASSERT_EQ(sent.back().c.mode, static_cast<int>(Mode::kPolicy));
    const int64_t now = sent.back().t + 100;  // the next command is a period away
    ASSERT_GT(r.nextCommandDueUs(), now);
    masa::lcmt_robot_command cmd = r.makeCommand();
    EXPECT_FALSE(r.poll(now, cmd)) << "no command is due yet";
    EXPECT_EQ(r.safeMode(), safe == SafeMode::kHold ? Mode::kHold : Mode::kDamping);
    r.stopNow(r.safeMode(), "stopped by SIGTERM");
    EXPECT_EQ(r.nextDeadline(now), now);
    ASSERT_TRUE(r.poll(now, cmd)) << "the safe command waited for its due time";
    EXPECT_EQ(cmd.mode, static_cast<int>(r.safeMode()));
    for (int k = 0; k < r.numJoints(); ++k) EXPECT_EQ(cmd.kp[k], safe == SafeMode::kHold ? cfg.hold_kp : 0.0);
    EXPECT_EQ(r.reason(), "stopped by SIGTERM");
    // One command at once, then the period again.
    EXPECT_FALSE(r.poll(now + 100, cmd));
    // Latched already: a second ending sends the latched command at once and keeps its reason.
    r.stopNow(Mode::kDamping, "another runner");
    ASSERT_TRUE(r.poll(now + 200, cmd));
    EXPECT_EQ(cmd.mode, static_cast<int>(r.safeMode()));
    EXPECT_EQ(r.reason(), "stopped by SIGTERM");
  }
}

TEST(DeployRunner, RepeatedStateIsStaleToo) {
  RunnerFixture f;
  PolicyRunner r(f.lp, testConfig(), 1);
  int64_t utime = 0;
  drive(r, *f.sim, 0, 1000000, 5000, utime);
  masa::lcmt_robot_command cmd = r.makeCommand();
  const masa::lcmt_robot_state same = stateOf(*f.sim, utime);  // the robot SDK re-sends its last state
  int64_t safe_at = -1;
  for (int64_t t = 1000000; t < 1200000 && safe_at < 0; t += 100) {
    if (t % 5000 == 0) r.onState(same, t);
    if (r.poll(t, cmd) && cmd.mode >= 2) safe_at = t;
  }
  ASSERT_GT(safe_at, 0);
  EXPECT_LE(safe_at - 995000, static_cast<int64_t>(r.watchdogBoundS() * 1e6));
}

// docs/inputs.md gap 2: one state with a far-future utime, from anyone on the robot's LAN, made
// every later real state a "repeat", and the watchdog latched the safe command.
TEST(DeployRunner, OneForgedFarFutureStateDoesNotStopTheRobot) {
  RunnerFixture f;
  PolicyRunner r(f.lp, testConfig(), 1);
  int64_t utime = 0;
  drive(r, *f.sim, 0, 1500000, 5000, utime);
  ASSERT_EQ(r.mode(), Mode::kPolicy);
  r.onState(stateOf(*f.sim, std::numeric_limits<int64_t>::max() - 1), 1502500);
  const int64_t taken = r.statesReceived();
  auto sent = drive(r, *f.sim, 1500000, 2500000, 5000, utime);
  ASSERT_FALSE(sent.empty());
  for (const Sent& s : sent) ASSERT_EQ(s.c.mode, static_cast<int>(Mode::kPolicy)) << "safe command at " << s.t << ": " << r.reason();
  EXPECT_EQ(r.statesReceived() - taken, 200) << "the real states after the forgery were not all taken";
  EXPECT_EQ(r.freshness().refusedAhead(), 1);
}

// docs/inputs.md gap 2: mutated copies of the robot's real state messages (bit flips, hostile
// lengths, truncation, splices), through the wire guard into the runner, interleaved with the real
// ones: no crash, and every command finite and within the joint range and the gain bounds.
TEST(DeployRunner, MutatedStateMessagesNeverGiveACommandOutsideTheLimits) {
  RunnerFixture f;
  PolicyRunner r(f.lp, testConfig(), 1);
  const DeployConfig c = testConfig();
  int64_t utime = 0, delivered = 0, refused = 0;
  masa::lcmt_robot_command cmd = r.makeCommand();
  masa::lcmt_robot_state decoded;
  for (int64_t t = 0; t < 3000000; t += 500) {
    if (t % 5000 == 0) {
      const masa::lcmt_robot_state real = stateOf(*f.sim, ++utime);
      std::vector<uint8_t> bytes(static_cast<std::size_t>(real.getEncodedSize()));
      real.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
      r.onState(real, t);
      transport::MessageMutator mutator(bytes, static_cast<uint64_t>(utime));
      for (int m = 0; m < 3; ++m) {
        const std::vector<uint8_t> hostile = mutator.next();
        if (transport::decodeChecked(hostile.data(), static_cast<int>(hostile.size()), decoded) != transport::WireVerdict::kOk) {
          ++refused;
          continue;
        }
        ++delivered;
        r.onState(decoded, t + 100 + m);
      }
    }
    if (!r.poll(t, cmd)) continue;
    for (int k = 0; k < r.numJoints(); ++k) {
      ASSERT_TRUE(std::isfinite(cmd.position[k]) && std::isfinite(cmd.velocity[k]) && std::isfinite(cmd.torque_ff[k]));
      ASSERT_GE(cmd.position[k], r.lowerLimit()[k]) << "joint " << k << " at " << t;
      ASSERT_LE(cmd.position[k], r.upperLimit()[k]) << "joint " << k << " at " << t;
      ASSERT_LE(std::abs(cmd.torque_ff[k]), r.torqueLimit()[k]);
      ASSERT_TRUE(cmd.kp[k] >= 0.0 && cmd.kp[k] <= c.max_kp && cmd.kd[k] >= 0.0 && cmd.kd[k] <= c.max_kd);
    }
  }
  EXPECT_GT(refused, 0) << "no mutation was refused by the wire guard";
  EXPECT_GT(delivered, 0) << "no mutation decoded: the runner was not reached";
  std::printf("robot state fuzz: %lld mutations decoded and given to the runner, %lld refused by the guard; mode %s\n",
              static_cast<long long>(delivered), static_cast<long long>(refused), modeName(r.mode()));
}

TEST(DeployRunner, NonFiniteStateGivesTheSafeCommandAtOnce) {
  for (const char* field : {"joint_position", "joint_velocity", "base_qx"}) {
    RunnerFixture f;
    PolicyRunner r(f.lp, testConfig(), 1);
    int64_t utime = 0;
    drive(r, *f.sim, 0, 1500000, 5000, utime);
    ASSERT_EQ(r.mode(), Mode::kPolicy);
    masa::lcmt_robot_state s = stateOf(*f.sim, ++utime);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (std::string(field) == "joint_position") s.joint_position[4] = nan;
    if (std::string(field) == "joint_velocity") s.joint_velocity[7] = std::numeric_limits<double>::infinity();
    if (std::string(field) == "base_qx") s.base_qx = nan;
    r.onState(s, 1500000);
    masa::lcmt_robot_command cmd = r.makeCommand();
    ASSERT_TRUE(r.poll(1500000, cmd)) << field;
    EXPECT_EQ(cmd.mode, static_cast<int>(Mode::kDamping)) << field;
    for (int k = 0; k < r.numJoints(); ++k) EXPECT_TRUE(std::isfinite(cmd.position[k])) << field;
    EXPECT_NE(r.reason().find("not finite"), std::string::npos) << r.reason();
  }
}

TEST(DeployRunner, EmergencyStopOnTheOrientationLimit) {
  RunnerFixture f;
  PolicyRunner r(f.lp, testConfig(), 1);
  int64_t utime = 0;
  drive(r, *f.sim, 0, 1500000, 5000, utime);
  masa::lcmt_robot_state s = stateOf(*f.sim, ++utime);
  const double roll = 0.9;  // beyond the default 0.8 rad
  s.base_qw = std::cos(roll / 2), s.base_qx = std::sin(roll / 2), s.base_qy = s.base_qz = 0;
  r.onState(s, 1500000);
  masa::lcmt_robot_command cmd = r.makeCommand();
  ASSERT_TRUE(r.poll(1500000, cmd));
  EXPECT_EQ(cmd.mode, static_cast<int>(Mode::kEmergencyStop));
  EXPECT_NE(r.reason().find("roll"), std::string::npos) << r.reason();
}

// The A1's crouch (walk-these-ways' fall response): on the orientation limit the targets leave the
// measured pose for the crouch pose at no more than crouch_max_rate, reach it, and stay there with
// the crouch gains, latched, even when the state then stops.
TEST(DeployRunner, EmergencyCrouchReachesTheCrouchPoseWithinItsRate) {
  RunnerFixture f;
  DeployConfig c = testConfig();
  c.emergency_response = EmergencyResponse::kCrouch;
  c.crouch_pose.clear();
  for (int leg = 0; leg < 4; ++leg) c.crouch_pose.insert(c.crouch_pose.end(), {0.0, 1.2, -2.4});
  c.crouch_max_rate = 1.0;
  c.crouch_kp = 30.0;
  c.crouch_kd = 1.5;
  PolicyRunner r(f.lp, c, 1);
  int64_t utime = 0;
  drive(r, *f.sim, 0, 1500000, 5000, utime);
  ASSERT_EQ(r.mode(), Mode::kPolicy);
  masa::lcmt_robot_state s = stateOf(*f.sim, ++utime);
  const double roll = 1.0;
  s.base_qw = std::cos(roll / 2), s.base_qx = std::sin(roll / 2), s.base_qy = s.base_qz = 0;
  // The robot has been thrown about: its joints are away from the last target.
  for (int k = 0; k < r.numJoints(); ++k) s.joint_position[k] += k % 2 ? 0.3 : -0.3;
  const std::vector<double> measured(s.joint_position.begin(), s.joint_position.end());
  r.onState(s, 1500000);
  masa::lcmt_robot_command cmd = r.makeCommand();
  ASSERT_TRUE(r.poll(1500000, cmd));
  ASSERT_EQ(cmd.mode, static_cast<int>(Mode::kEmergencyStop));
  EXPECT_TRUE(r.crouching());
  std::vector<double> prev = measured;
  int64_t last_t = 1500000 - static_cast<int64_t>(r.periodS() * 1e6);
  double farthest = 0;  // rad between the measured pose and the crouch pose
  for (int k = 0; k < r.numJoints(); ++k) farthest = std::max(farthest, std::abs(c.crouch_pose[k] - measured[k]));
  int64_t reached_at = -1, last_utime = 0;
  for (int64_t t = 1500000, n = 0; t < 6000000; t += 500) {
    if (t > 1500000 && t < 2000000 && t % 5000 == 0) r.onState(stateOf(*f.sim, ++utime), t);  // then the state stops
    if (t > 1500000 && !r.poll(t, cmd)) continue;
    ++n;
    ASSERT_EQ(cmd.mode, static_cast<int>(Mode::kEmergencyStop)) << "at " << t;
    bool at_pose = true;
    for (int k = 0; k < r.numJoints(); ++k) {
      ASSERT_LE(std::abs(cmd.position[k] - prev[k]), c.crouch_max_rate * (t - last_t) * 1e-6 + 1e-12)
          << "joint " << k << " moved too fast at " << t;
      // As the robot sees it: between the commands' utimes (failed before: the wall clock read
      // after the step was computed, microseconds apart here).
      if (last_utime > 0) {
        ASSERT_LE(std::abs(cmd.position[k] - prev[k]), c.crouch_max_rate * (cmd.utime - last_utime) * 1e-6 + 1e-12)
            << "joint " << k << " moved too fast between utimes at " << t;
      }
      ASSERT_EQ(cmd.kp[k], c.crouch_kp);
      ASSERT_EQ(cmd.kd[k], c.crouch_kd);
      at_pose = at_pose && cmd.position[k] == c.crouch_pose[k];
    }
    if (at_pose && reached_at < 0) reached_at = t;
    prev.assign(cmd.position.begin(), cmd.position.end());
    last_t = t;
    last_utime = cmd.utime;
  }
  ASSERT_GT(reached_at, 0) << "the crouch pose was never reached";
  // No faster than the rate allows, and not much slower: one period of slack.
  const double took_s = (reached_at - 1500000) * 1e-6 + r.periodS();
  EXPECT_GE(took_s + 1e-9, farthest / c.crouch_max_rate);
  EXPECT_LE(took_s, farthest / c.crouch_max_rate + 2 * r.periodS());
  EXPECT_NE(r.reason().find("emergency stop"), std::string::npos) << r.reason();
}

TEST(DeployRunner, CrouchPoseOfTheWrongSizeOrOutsideTheLimitsIsRefused) {
  RunnerFixture f;
  DeployConfig c = testConfig();
  c.emergency_response = EmergencyResponse::kCrouch;
  c.crouch_pose = {0.0, 1.2, -2.4};
  try {
    PolicyRunner r(f.lp, c, 1);
    FAIL() << "a 3-value crouch pose was accepted for 12 joints";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("has 3 values"), std::string::npos) << e.what();
  }
  c.crouch_pose.clear();
  for (int leg = 0; leg < 4; ++leg) c.crouch_pose.insert(c.crouch_pose.end(), {0.0, 1.2, -2.69});  // calf limit -2.697 less 0.05
  try {
    PolicyRunner r(f.lp, c, 1);
    FAIL() << "a crouch pose beyond the position margin was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("FR_calf_joint"), std::string::npos) << e.what();
  }
  EXPECT_THROW(loadDeployConfig("", {"emergency.response=crouch"}), ConfigError);  // no pose
  const std::string pose = "emergency.crouch_pose=[0, 1.2, -2.4, 0, 1.2, -2.4, 0, 1.2, -2.4, 0, 1.2, -2.4]";
  EXPECT_THROW(loadDeployConfig("", {"emergency.response=crouch", pose, "emergency.crouch_kp=500"}), ConfigError);  // above limits.max_kp
  EXPECT_NO_THROW(loadDeployConfig("", {"emergency.response=crouch", pose}));
}

// Every command of a runner with random networks, on random states, keeps the limits.
TEST(DeployRunner, LimitsHoldOnEveryCommandForRandomPolicies) {
  for (uint64_t seed : {1, 2, 3}) {
    RunnerFixture f;
    Rng rng(seed);
    std::normal_distribution<float> w(0.0f, 3.0f);  // large weights: actions far beyond [-1, 1]
    for (int i = 0; i < f.lp.model->params().size(); ++i) f.lp.model->params().values()[i] = w(rng);
    DeployConfig c = testConfig();
    c.calibration_settle_s = 0;
    c.calibration_max_rate = 50;
    c.max_target_rate = 5.0;  // tight enough to bind
    c.action_clip = 3.0;      // the task clamps to 1 anyway
    c.max_kp = 30;            // below the A1's 40: must bind
    c.position_margin = 0.4;  // hips +-0.403 rad: the A1's targets (stand +-0.4, +-0.25 per action) exceed it
    PolicyRunner r(f.lp, c, 1);
    std::normal_distribution<double> noise(0.0, 1.0);
    masa::lcmt_robot_command cmd = r.makeCommand();
    int64_t last_t = -1, last_utime = 0, policy_commands = 0;
    std::vector<double> prev;
    for (int64_t t = 0, utime = 0; t < 1000000; t += 500) {
      if (t % 5000 == 0) {
        masa::lcmt_robot_state s = stateOf(*f.sim, ++utime);
        for (int k = 0; k < r.numJoints(); ++k) {
          s.joint_position[k] += 0.5 * noise(rng);
          s.joint_velocity[k] = 5 * noise(rng);
        }
        s.base_y = 0.1 * noise(rng), s.base_vx = noise(rng), s.base_wz = noise(rng);
        r.onState(s, t);
      }
      if (!r.poll(t, cmd)) continue;
      for (int k = 0; k < r.numJoints(); ++k) {
        ASSERT_TRUE(std::isfinite(cmd.position[k]));
        ASSERT_GE(cmd.position[k], r.lowerLimit()[k]) << "joint " << k << " at " << t;
        ASSERT_LE(cmd.position[k], r.upperLimit()[k]) << "joint " << k << " at " << t;
        ASSERT_LE(std::abs(cmd.torque_ff[k]), r.torqueLimit()[k]);
        ASSERT_GE(cmd.kp[k], 0.0);
        ASSERT_LE(cmd.kp[k], c.max_kp);
        ASSERT_GE(cmd.kd[k], 0.0);
        ASSERT_LE(cmd.kd[k], c.max_kd);
        if (cmd.mode == static_cast<int>(Mode::kPolicy) && !prev.empty()) {
          ASSERT_LE(std::abs(cmd.position[k] - prev[k]), c.max_target_rate * (t - last_t) * 1e-6 + 1e-12)
              << "joint " << k << " moved too fast at " << t;
          ASSERT_LE(std::abs(cmd.position[k] - prev[k]), c.max_target_rate * (cmd.utime - last_utime) * 1e-6 + 1e-12)
              << "joint " << k << " moved too fast between the commands' utimes at " << t;
        }
      }
      policy_commands += cmd.mode == static_cast<int>(Mode::kPolicy);
      prev.assign(cmd.position.begin(), cmd.position.end());
      last_t = t;
      last_utime = cmd.utime;
    }
    EXPECT_GT(policy_commands, 20) << "seed " << seed;
  }
}

TEST(DeployRunner, CalibrationRampNeverExceedsItsRateAndReachesTheNominalPose) {
  RunnerFixture f;
  DeployConfig c = testConfig();
  c.calibration_max_rate = 0.5;
  PolicyRunner r(f.lp, c, 1);
  // The robot lies folded: every joint at the far end of its range from the nominal pose.
  masa::lcmt_robot_state s = stateOf(*f.sim, 1);
  for (int k = 0; k < r.numJoints(); ++k)
    s.joint_position[k] = r.nominalPose()[k] - r.lowerLimit()[k] > r.upperLimit()[k] - r.nominalPose()[k] ? r.lowerLimit()[k]
                                                                                                    : r.upperLimit()[k];
  masa::lcmt_robot_command cmd = r.makeCommand();
  std::vector<double> prev(s.joint_position.begin(), s.joint_position.end());
  int64_t last_t = -1, calibrating = 0;
  bool reached = false;
  for (int64_t t = 0; t < 8000000 && !reached; t += 1000) {
    if (t % 2000 == 0) {
      ++s.utime;
      r.onState(s, t);
    }
    if (!r.poll(t, cmd)) continue;
    if (cmd.mode != static_cast<int>(Mode::kCalibrating)) {
      reached = cmd.mode == static_cast<int>(Mode::kPolicy);
      break;
    }
    const double dt = last_t < 0 ? r.periodS() : (t - last_t) * 1e-6;
    for (int k = 0; k < r.numJoints(); ++k)
      ASSERT_LE(std::abs(cmd.position[k] - prev[k]), c.calibration_max_rate * dt + 1e-9) << "joint " << k << " at " << t;
    prev.assign(cmd.position.begin(), cmd.position.end());
    last_t = t;
    ++calibrating;
  }
  EXPECT_TRUE(reached) << "the policy never took over";
  for (int k = 0; k < r.numJoints(); ++k) EXPECT_NEAR(prev[k], r.nominalPose()[k], 1e-12);
  EXPECT_GT(calibrating, 100);  // the folded pose is more than 2 s of ramp away
}

TEST(DeployRunner, ControlStepAllocatesNothing) {
  if (!test::allocationCountingEnabled()) GTEST_SKIP() << "allocation counting disabled (sanitizer)";
  RunnerFixture f;
  PolicyRunner r(f.lp, testConfig(), 1);
  int64_t utime = 0;
  drive(r, *f.sim, 0, 1500000, 5000, utime);
  ASSERT_EQ(r.mode(), Mode::kPolicy);
  masa::lcmt_robot_state s = stateOf(*f.sim, utime);
  masa::lcmt_robot_command cmd = r.makeCommand();
  const int64_t steps_before = r.policySteps();
  const long before = test::allocationCount();
  for (int64_t t = 1500000; t < 2500000; t += 500) {
    if (t % 5000 == 0) {
      ++s.utime;
      r.onState(s, t);
    }
    if (t % 2500 == 0) r.warmUp();
    r.poll(t, cmd);
  }
  EXPECT_EQ(test::allocationCount() - before, 0);
  EXPECT_GE(r.policySteps() - steps_before, 45);
}

// The cache warm-up before a command (realtime.warm_up_us) changes no command.
TEST(DeployRunner, WarmUpChangesNoCommand) {
  RunnerFixture f, g;
  PolicyRunner plain(f.lp, testConfig(), 1), warmed(g.lp, testConfig(), 1);
  masa::lcmt_robot_command a = plain.makeCommand(), b = warmed.makeCommand();
  Rng rng(4);
  std::normal_distribution<double> noise(0.0, 0.2);
  int compared = 0;
  for (int64_t t = 0, utime = 0; t < 3000000; t += 500) {
    if (t % 2000 == 0) {
      masa::lcmt_robot_state s = stateOf(*f.sim, ++utime);
      for (double& q : s.joint_position) q += noise(rng);
      plain.onState(s, t);
      warmed.onState(s, t);
    }
    if (t % 1500 == 0) warmed.warmUp();
    const bool pa = plain.poll(t, a), pb = warmed.poll(t, b);
    ASSERT_EQ(pa, pb) << "at " << t;
    if (!pa) continue;
    for (int k = 0; k < plain.numJoints(); ++k) ASSERT_EQ(a.position[k], b.position[k]) << "joint " << k << " at " << t;
    compared += a.mode == static_cast<int>(Mode::kPolicy);
  }
  EXPECT_GT(compared, 60);
}

// realtime: settings the system refuses are said, not fatal; bad values are config errors.
TEST(DeployRealtime, RefusedSettingsAreSaidAndBadValuesAreErrors) {
  EXPECT_EQ(applyRealtime(RealtimeSettings{}), "normal scheduling");
  RealtimeSettings no_such_core;
  no_such_core.cpu = 4000;  // sched_setaffinity fails; this process keeps its cores
  EXPECT_NE(applyRealtime(no_such_core).find("NOT pinned to core 4000"), std::string::npos);
  EXPECT_THROW(loadDeployConfig("", {"realtime.priority=100"}), ConfigError);
  EXPECT_THROW(loadDeployConfig("", {"realtime.cpu=1.5"}), ConfigError);
  EXPECT_THROW(loadDeployConfig("", {"realtime.busy_poll_us=-1"}), ConfigError);
  const DeployConfig c = loadDeployConfig("", {"realtime.priority=50", "realtime.warm_up_us=1000"});
  EXPECT_EQ(c.realtime.priority, 50);
  EXPECT_EQ(c.warm_up_us, 1000);
}

TEST(DeployConfig, UnknownKeyAndBadValueNameTheKey) {
  const std::string dir = testing::TempDir();
  const std::string file = dir + "/robot.yaml";
  std::ofstream(file) << "watchdog:\n  stale_afer_s: 0.1\n";
  try {
    loadDeployConfig(file);
    FAIL() << "an unknown key was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("robot.yaml: key 'watchdog.stale_afer_s': unknown key"), std::string::npos)
        << e.what();
  }
  try {
    loadDeployConfig("", {"safe.mode=limp"});
    FAIL() << "a bad safe mode was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("command line: key 'safe.mode'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(loadDeployConfig("", {"watchdog.stale_after_s=0"}), ConfigError);
  EXPECT_DOUBLE_EQ(loadDeployConfig("", {"limits.max_kp=12"}).max_kp, 12.0);
}

TEST(DeployRunner, TasksThatCannotRunOnARobotStateAreRefusedWithTheReason) {
  // trifinger_lift's observation needs the cube: not in a robot state message.
  config::RunConfig rc = config::loadRunConfig(config::defaultConfigsDir(), {"task=trifinger_lift"});
  policy::LoadedPolicy lp;
  lp.config = rc;
  lp.spec = sym::SymmetrySpec::load(rc.spec_path);
  lp.model = std::make_unique<model::ActorCritic<float>>(lp.spec, rc.model);
  try {
    PolicyRunner r(lp, testConfig(), 1);
    FAIL() << "trifinger_lift was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot run on a robot's state alone"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace masa::deploy
