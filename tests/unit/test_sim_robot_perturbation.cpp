// masa_sim_robot's perturbation (deploy/sim_robot/perturbation.hpp, issue #52 item 2): --perturb and
// --perturb-file build env.randomization (replacing the policy's own); the perturbed robot moves
// otherwise than the nominal one under the same commands; a weaker motor gives less torque for the
// same command; no perturbation is bit for bit the nominal robot; a bad value is refused naming
// the key; the reported state's noise is reproducible. Over LCM: deploy_sim_robot.sh perturbed.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/core/config_error.hpp"
#include "deploy/sim_robot/perturbation.hpp"
#include "deploy/sim_robot/sim_robot.hpp"
#include "task_test_support.hpp"

namespace masa::test {
namespace {

struct PerturbedRobot {
  task::TaskFactory factory;
  std::unique_ptr<task::Task> task;
  std::unique_ptr<deploy::SimRobot> robot;
};

std::unique_ptr<PerturbedRobot> makePerturbedRobot(const std::vector<std::string>& perturb, uint64_t seed = 0) {
  std::map<std::string, std::string> origin;
  bool perturbed = false;
  YAML::Node env = deploy::perturbedEnv(shippedEnv("a1_beam"), perturb, "", origin, &perturbed);
  auto r = std::unique_ptr<PerturbedRobot>(new PerturbedRobot{task::TaskFactory(task::taskCatalog(), "a1_beam", shippedSpec("a1_beam"), env, origin),
                                            nullptr, nullptr});
  r->task = r->factory.create();
  Rng rng(seed);
  r->task->reset(rng);
  r->robot = std::make_unique<deploy::SimRobot>(*r->task, shippedSpec("a1_beam"));
  return r;
}

// Every joint held at its present angle by a PD law (kp 40, kd 1), plus torque_ff.
masa::lcmt_robot_command holdCommand(const deploy::SimRobot& robot, double torque_ff) {
  masa::lcmt_robot_command c{};
  const int n = robot.numJoints();
  c.num_joints = n;
  c.position = robot.jointAngles();
  c.velocity.assign(n, 0.0);
  c.kp.assign(n, 40.0);
  c.kd.assign(n, 1.0);
  c.torque_ff.assign(n, torque_ff);
  c.mode = 1;
  return c;
}

std::vector<double> stateAfter(PerturbedRobot& r, int steps) {
  const masa::lcmt_robot_command c = holdCommand(*r.robot, 0.0);
  for (int i = 0; i < steps; ++i) r.robot->step(c);
  r.robot->updateKinematics();
  masa::lcmt_robot_state st{};
  r.robot->fillState(st, {}, 0.0);
  std::vector<double> out = st.joint_position;
  out.insert(out.end(), {st.base_x, st.base_y, st.base_z, st.base_qw, st.base_qx, st.base_qy, st.base_qz});
  return out;
}

TEST(SimRobotPerturbation, KeysWithOrWithoutThePrefixAndAFileReplaceTheTrainingRandomization) {
  YAML::Node env = shippedEnv("a1_beam");
  env["randomization"] = YAML::Load("{per_limb: true, obs_noise_std: 0.1}");
  const std::string file = ::testing::TempDir() + "/perturbation.yaml";
  std::ofstream(file) << "env:\n  randomization:\n    geom_friction_scale: 0.5\n    mass_scale: 2.0\n";
  std::map<std::string, std::string> origin{{"env.randomization.per_limb", "configs"}};
  bool perturbed = false;
  const YAML::Node out = deploy::perturbedEnv(env, {"env.randomization.mass_scale=[1.2, 1.2]", "actuator_strength=0.8"},
                                              file, origin, &perturbed);
  EXPECT_TRUE(perturbed);
  EXPECT_FALSE(out["randomization"]["per_limb"]) << "the training randomization was kept";
  EXPECT_FALSE(out["randomization"]["obs_noise_std"]);
  EXPECT_EQ(out["randomization"]["mass_scale"][0].as<double>(), 1.2) << "--perturb wins over the file";
  EXPECT_EQ(out["randomization"]["actuator_strength"].as<double>(), 0.8);
  EXPECT_EQ(out["randomization"]["geom_friction_scale"].as<double>(), 0.5);
  EXPECT_EQ(origin["env.randomization.mass_scale"], "--perturb");
  EXPECT_EQ(origin["env.randomization.geom_friction_scale"], file);
  EXPECT_EQ(origin.count("env.randomization.per_limb"), 0u);
  EXPECT_TRUE(env["randomization"]["per_limb"]) << "the policy's env was changed";
  EXPECT_THROW(deploy::perturbedEnv(env, {"mass_scale"}, "", origin, &perturbed), std::runtime_error);
}

TEST(SimRobotPerturbation, NoPerturbationIsBitForBitTheNominalRobot) {
  std::map<std::string, std::string> origin;
  bool perturbed = true;
  const YAML::Node env = shippedEnv("a1_beam");
  const YAML::Node out = deploy::perturbedEnv(env, {}, "", origin, &perturbed);
  EXPECT_FALSE(perturbed);
  EXPECT_EQ(YAML::Dump(out), YAML::Dump(env));
  auto a = makePerturbedRobot({}), b = makePerturbedRobot({});
  EXPECT_EQ(a->task->randomization(), nullptr);
  EXPECT_EQ(stateAfter(*a, 200), stateAfter(*b, 200));
}

TEST(SimRobotPerturbation, APerturbedRobotMovesOtherwiseUnderTheSameCommandsReadBackFromItsModel) {
  auto nominal = makePerturbedRobot({});
  auto heavy = makePerturbedRobot({"env.randomization.mass_scale=1.3", "geom_friction_scale=0.6"});
  const mjModel* m0 = nominal->task->model();
  const mjModel* m1 = heavy->task->model();
  for (int b = 1; b < m0->nbody; ++b) EXPECT_NEAR(m1->body_mass[b], 1.3 * m0->body_mass[b], 1e-9 * m0->body_mass[b]);
  for (int g = 0; g < m0->ngeom; ++g) EXPECT_NEAR(m1->geom_friction[3 * g], 0.6 * m0->geom_friction[3 * g], 1e-12);
  EXPECT_NE(deploy::describePerturbation(*heavy->task).find("geom friction x0.600"), std::string::npos)
      << deploy::describePerturbation(*heavy->task);
  const std::vector<double> s0 = stateAfter(*nominal, 200), s1 = stateAfter(*heavy, 200);
  double largest = 0;
  for (std::size_t k = 0; k < s0.size(); ++k) largest = std::max(largest, std::abs(s0[k] - s1[k]));
  EXPECT_GT(largest, 1e-3) << "a 30% heavier robot held by the same PD law sagged no differently";
}

TEST(SimRobotPerturbation, AWeakerMotorGivesLessTorqueForTheSameCommand) {
  auto nominal = makePerturbedRobot({});
  auto weak = makePerturbedRobot({"actuator_strength=0.7"});
  for (auto* r : {nominal.get(), weak.get()}) {
    masa::lcmt_robot_command c = holdCommand(*r->robot, 1.0);
    std::fill(c.kp.begin(), c.kp.end(), 0.0);
    std::fill(c.kd.begin(), c.kd.end(), 0.0);
    r->robot->step(c);
  }
  masa::lcmt_robot_state s0{}, s1{};
  nominal->robot->fillState(s0, {}, 0.0);
  weak->robot->fillState(s1, {}, 0.0);
  for (int k = 0; k < s0.num_joints; ++k) {
    EXPECT_NEAR(s0.joint_torque[k], 1.0, 1e-9) << "joint " << k;
    EXPECT_NEAR(s1.joint_torque[k], 0.7, 1e-9) << "joint " << k << ": the driver converted with the perturbed gear";
  }
}

TEST(SimRobotPerturbation, ABadValueIsRefusedNamingTheKeyAndWhereItCameFrom) {
  for (const std::string bad : {"mass_scale=-1", "mass_scale=[1.3, 1.1]", "actuator_strength=.nan", "mass_scal=1.2"}) {
    try {
      makePerturbedRobot({bad});
      ADD_FAILURE() << bad << " was taken";
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      const std::string key = bad.substr(0, bad.find('='));
      EXPECT_NE(what.find("env.randomization." + key), std::string::npos) << what;
      EXPECT_NE(what.find("--perturb"), std::string::npos) << what;
    }
  }
}

TEST(SimRobotPerturbation, TheReportedStatesNoiseAndBiasAreReproducibleAndBounded) {
  task::RandomizationConfig config;
  config.obs_noise_std = 0.01;
  config.obs_bias = 0.05;
  auto noisy = [&](uint64_t seed) {
    Rng rng(seed);
    deploy::StateNoise noise(config, 3, rng);
    masa::lcmt_robot_state st{};
    st.num_joints = 3;
    st.joint_position.assign(3, 0.0);
    st.joint_velocity.assign(3, 0.0);
    noise.apply(st);
    std::vector<double> out = st.joint_position;
    out.insert(out.end(), st.joint_velocity.begin(), st.joint_velocity.end());
    return out;
  };
  EXPECT_EQ(noisy(1), noisy(1));
  EXPECT_NE(noisy(1), noisy(2));
  for (double x : noisy(3)) {
    EXPECT_NE(x, 0.0);
    EXPECT_LT(std::abs(x), 0.05 + 6 * 0.01);
  }
  task::RandomizationConfig none;
  Rng rng(1);
  EXPECT_FALSE(deploy::StateNoise(none, 3, rng).active());
}

}  // namespace
}  // namespace masa::test
