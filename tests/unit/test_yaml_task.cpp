// The task written in YAML (common/sim/yaml/yaml_task.cpp, docs/yaml_task.md) on robots without task
// code: the C4 walker's locomotion task (configs/tasks/c4_walker.yaml) and the mirror-symmetric twin
// arm of tests/data. The physics verifier proves their observations and rewards symmetric; the
// terms measure what they say; sensors are read for the state a step ends in; and every mistake a
// user can write is an error naming the key, the name and what would be right.
#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <regex>

#include "common/core/config_error.hpp"
#include "task_test_support.hpp"

namespace masa::task {
namespace {

using test::editedEnv;
using test::editedSpec;
using test::envFactory;

const std::string kYamlData = MASA_TEST_DATA_DIR;
constexpr const char* kWalker = "c4_walker";

// The message of what building the task throws ("" when nothing is thrown).
std::string buildError(const YAML::Node& env, const sym::SymmetrySpec& spec) {
  try {
    TaskFactory f(task::taskCatalog(), kWalker, spec, env);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}
std::string buildError(const YAML::Node& env) { return buildError(env, test::shippedSpec(kWalker)); }

TEST(YamlTask, C4WalkerLocomotionIsProvenSymmetricObservationRewardAndDynamics) {
  const TaskFactory f = test::runConfigFactory(kWalker);
  SymmetryVerifierOptions opt;
  opt.num_states = 6;
  opt.diagnosis_states = 2;
  const SymmetryReport r = verifySymmetry(f, opt);
  EXPECT_TRUE(r.passed()) << r.summary(8);
  EXPECT_LT(r.reward_error, 1e-9);
}

TEST(YamlTask, AComponentTheRotationMixesWithAnotherIsRefused) {
  // x alone of the torso position: a quarter turn about z makes it y.
  const YAML::Node env = editedEnv(kWalker, [](YAML::Node& e) { e["observation"]["central"]["torso_height"]["components"] = "x"; });
  const std::string e = buildError(env);
  EXPECT_NE(e.find("a world position ('torso_height') does not transform linearly under the C4 rotation about z"),
            std::string::npos)
      << e;
}

TEST(YamlTask, ForwardLateralAndUprightTermsMeasureTheTorsoAgainstTheHeading) {
  const TaskFactory f = test::runConfigFactory(kWalker);
  auto t = f.create();
  Rng rng(3);
  t->reset(rng);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> act(t->actDim());
  for (int s = 0; s < 20; ++s) {
    for (float& a : act) a = u(rng);
    if (t->step(act.data()).terminated) t->reset(rng);
  }
  for (float& a : act) a = u(rng);
  ASSERT_FALSE(t->step(act.data()).terminated);
  const std::vector<float> o = test::observation(*t);
  const int h = test::obsIndex(*t, "central.heading[0]");
  const Eigen::Vector3d heading(o[h], o[h + 1], 0.0);
  EXPECT_NEAR(heading.norm(), 1.0, 1e-6);
  const Eigen::Vector3d v(test::jointQvel(*t, "root"));
  const double weight_forward = 1.0, weight_lateral = -0.5, weight_upright = 0.1;
  EXPECT_NEAR(test::rewardTerm(*t, "forward"), weight_forward * v.dot(heading), 1e-6);
  EXPECT_NEAR(test::rewardTerm(*t, "lateral"), weight_lateral * std::abs(v.x() * -heading.y() + v.y() * heading.x()),
              1e-6);
  const double up = t->data()->xmat[9 * mj_name2id(t->model(), mjOBJ_BODY, "torso") + 8];
  EXPECT_EQ(test::rewardTerm(*t, "upright"), up > 0.9 ? weight_upright : 0.0);
}

TEST(YamlTask, TheHeadingIsDrawnAtEveryResetAndSeedsRepeat) {
  const TaskFactory f = test::runConfigFactory(kWalker);
  auto t = f.create();
  Rng rng(11);
  std::vector<float> seen;
  for (int k = 0; k < 3; ++k) {
    t->reset(rng);
    seen.push_back(test::observation(*t)[test::obsIndex(*t, "central.heading[0]")]);
  }
  EXPECT_NE(seen[0], seen[1]);
  EXPECT_NE(seen[1], seen[2]);
  test::expectSameSeedBitIdenticalOtherSeedDiffers(
      [&](std::uint64_t seed) { return test::recordTrajectory(f, seed, {.steps = 60}); }, 5, 6);
}

// q and -q are one orientation: the observation picks w >= 0, so both give the same values.
TEST(YamlTask, AQuaternionAndItsNegativeAreObservedAlike) {
  const TaskFactory f = test::runConfigFactory(kWalker);
  auto t = f.create();
  Rng rng(2);
  t->reset(rng);
  double* q = test::jointQpos(*t, "root") + 3;
  const double turned[4] = {std::cos(1.2), 0.0, 0.0, std::sin(1.2)};  // 137 deg about z
  std::copy(turned, turned + 4, q);
  mj_forward(t->model(), t->data());
  const std::vector<float> plus = test::observation(*t);
  for (int k = 0; k < 4; ++k) q[k] = -q[k];
  mj_forward(t->model(), t->data());
  const std::vector<float> minus = test::observation(*t);
  EXPECT_EQ(plus, minus);
  EXPECT_GT(plus[test::obsIndex(*t, "central.torso_quat_w")], 0.0f);
}

// A sensor is read for the state the step ended in, not the one MuJoCo computed it for (the start
// of the step's last substep): a framelinvel sensor on the torso equals the free joint's velocity.
TEST(YamlTask, SensorsAreReadForTheStateTheStepEndsIn) {
  std::string xml = test::readTextFile(kYamlData + "/c4_walker.xml");
  xml = std::regex_replace(xml, std::regex("</actuator>"),
                           "</actuator>\n  <sensor><framelinvel name=\"torso_vel\" objtype=\"body\" objname=\"torso\"/>"
                           "</sensor>");
  const std::string path = ::testing::TempDir() + "/c4_walker_with_sensor.xml";
  std::ofstream(path) << xml;
  YAML::Node env = test::shippedEnv(kWalker);
  env["model_file"] = path;
  env["observation"]["central"]["torso_lin_vel"] = YAML::Load("{source: sensor, sensor: torso_vel}");
  const TaskFactory f = envFactory(kWalker, env);
  auto t = f.create();
  Rng rng(1);
  t->reset(rng);
  const int at = test::obsIndex(*t, "central.torso_lin_vel[0]");
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> act(t->actDim());
  double worst = 0.0;
  for (int s = 0; s < 30; ++s) {
    for (float& a : act) a = u(rng);
    if (t->step(act.data()).terminated) break;
    const std::vector<float> o = test::observation(*t);
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(double(o[at + c]) - test::jointQvel(*t, "root")[c]));
  }
  EXPECT_LT(worst, 1e-5);

  env["observation"]["central"]["torso_lin_vel"]["sensor"] = "torso_velocity";
  const std::string e = buildError(env);
  EXPECT_NE(e.find("no sensor named 'torso_velocity' (it has: torso_vel)"), std::string::npos) << e;
  EXPECT_NE(e.find("env.observation.central.torso_lin_vel.sensor"), std::string::npos) << e;
}

TEST(YamlTask, MistakesNameTheKeyAndWhatWouldBeRight) {
  struct Case {
    const char* what;
    std::function<void(YAML::Node&)> edit;
    std::vector<const char*> says;
  };
  const std::vector<Case> cases = {
      {"unknown key in a source",
       [](YAML::Node& e) { e["observation"]["central"]["torso_height"]["bodies"] = "torso"; },
       {"env.observation.central.torso_height.bodies", "unknown key; valid keys here: source, body, components"}},
      {"unknown body",
       [](YAML::Node& e) { e["observation"]["central"]["torso_lin_vel"]["body"] = "trunk"; },
       {"env.observation.central.torso_lin_vel.body", "no body named 'trunk'", "torso, leg0"}},
      {"unknown joint in a limb template",
       [](YAML::Node& e) { e["observation"]["limb"]["hip_pos"]["joint"] = "hip_{limb}"; },
       {"env.observation.limb.hip_pos.joint", "no joint named 'hip_0'"}},
      {"a limb name without {limb}",
       [](YAML::Node& e) { e["observation"]["limb"]["hip_pos"]["joint"] = "hip0"; },
       {"one joint per limb", "{limb}"}},
      {"unknown action entry",
       [](YAML::Node& e) { e["observation"]["limb"]["hip_vel"]["action"] = "thigh"; },
       {"no limb action entry 'thigh' (hip, knee)"}},
      {"unknown source",
       [](YAML::Node& e) { e["observation"]["central"]["torso_height"]["source"] = "body_height"; },
       {"unknown source 'body_height'", "body_pos"}},
      {"an entry the spec does not have",
       [](YAML::Node& e) { e["observation"]["central"]["torso_xy"] = YAML::Load("{source: body_pos, body: torso}"); },
       {"no central observation entry 'torso_xy'", "torso_height, torso_lin_vel"}},
      {"an entry left without a source",
       [](YAML::Node& e) { e["observation"]["limb"].remove("knee_action"); },
       {"env.observation.limb.knee_action", "missing", "kind invariant"}},
      {"a source of the wrong size",
       [](YAML::Node& e) { e["observation"]["central"]["torso_height"]["components"] = "xz"; },
       {"gives 2 values", "holds 1"}},
      {"an orientation a rotation cannot map linearly",
       [](YAML::Node& e) { e["observation"]["central"]["torso_height"] = YAML::Load("{source: body_euler, body: torso, angle: yaw}"); },
       {"an Euler angle", "does not transform linearly", "quaternion"}},
      {"a velocity of a body without a free joint",
       [](YAML::Node& e) { e["reward"]["forward"]["body"] = "leg0"; },
       {"env.reward.forward.body", "has no free joint", "sensor"}},
      {"unknown reward type",
       [](YAML::Node& e) { e["reward"]["forward"]["type"] = "speed"; },
       {"env.reward.forward.type", "unknown type 'speed'", "forward_velocity"}},
      {"unknown termination body",
       [](YAML::Node& e) { e["termination"]["fallen"]["body"] = "base"; },
       {"env.termination.fallen.body", "no body named 'base'"}},
      {"a weight of no term",
       [](YAML::Node& e) { e["weights"]["forwards"] = 1.0; },
       {"env.weights.forwards", "unknown task parameter"}},
      {"a misspelt section",
       [](YAML::Node& e) { e["rewards"] = e["reward"]; },
       {"env.rewards", "unknown task parameter"}},
      {"a heading term on an axis the rotation moves",
       [](YAML::Node& e) { e["reward"]["facing"] = YAML::Load("{type: heading, body: torso, axis: x}"); },
       {"env.reward.facing.axis", "body 'torso'", "another of its axes takes the place of its local x axis"}},
      {"a pose of nothing",
       [](YAML::Node& e) { e["pose"]["ankle"] = 1.0; },
       {"env.pose.ankle", "neither an action entry", "hip, knee"}},
      // YAML's .nan and .inf are numbers to yaml-cpp: refused by key before anything uses them.
      {"an infinite reward target",
       [](YAML::Node& e) { e["reward"]["forward"]["target"] = ".inf"; },
       {"env.reward.forward.target", "expected a finite number"}},
      {"a NaN pose",
       [](YAML::Node& e) { e["pose"]["hip"] = ".nan"; },
       {"env.pose.hip", "expected a finite number"}},
      {"a NaN heading",
       [](YAML::Node& e) { e["heading"] = YAML::Load("{direction: [.nan, 1]}"); },
       {"env.heading.direction", "expected finite numbers"}},
      {"a pose the rotation does not keep",
       [](YAML::Node& e) { e["pose"]["knee0"] = 0.3; },
       {"env.pose", "the pose is not symmetric", "limb0.knee"}},
  };
  for (const Case& c : cases) {
    const std::string e = buildError(editedEnv(kWalker, c.edit));
    EXPECT_FALSE(e.empty()) << c.what << ": accepted";
    for (const char* s : c.says) EXPECT_NE(e.find(s), std::string::npos) << c.what << ": " << e << "\n  lacks: " << s;
  }
}

TEST(YamlTask, AKindThatDoesNotMatchTheSourceIsNamedWithTheRightOne) {
  // A joint follows its action: 'odd' (flipping at each quarter turn) is not how the hip moves.
  const sym::SymmetrySpec odd_hip = editedSpec(kWalker, [](YAML::Node& root) {
    for (auto e : root["observation"]["limb"])
      if (e["name"].as<std::string>() == "hip_pos") e["kind"] = "odd";
  });
  const std::string e = buildError(test::shippedEnv(kWalker), odd_hip);
  EXPECT_NE(e.find("the joint of action 'hip' transforms under the C4 rotation about z as kind 'invariant'"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("not as the kind 'odd'"), std::string::npos) << e;
}

// The twin arm of tests/data: a mirror, a central waist joint and a carried ball.
const char* kTwinArmEnv = R"(
task_code: yaml
model_file: )" MASA_TEST_DATA_DIR R"(/twin_arm.xml
observation:
  central:
    waist_pos: {source: joint_pos, action: waist}
    waist_vel: {source: joint_vel, joint: waist}
    ball_pos: {source: body_pos, body: ball}
    ball_vel: {source: body_lin_vel, body: ball}
    ball_ang_vel: {source: body_ang_vel, body: ball}
  limb:
    shoulder_pos: {source: joint_pos, action: shoulder}
    elbow_pos: {source: joint_pos, action: elbow}
    shoulder_vel: {source: joint_vel, action: shoulder}
    elbow_vel: {source: joint_vel, action: elbow}
    shoulder_action: {source: last_action, action: shoulder}
    elbow_action: {source: last_action, action: elbow}
reward:
  alive: {type: alive}
  effort: {type: action_squared}
reset: {joint_noise: 0.3, velocity_noise: 0.3}
)";

TEST(YamlTask, MirrorRobotWithACentralJointAndACarriedBallIsProvenSymmetric) {
  const sym::SymmetrySpec spec = sym::SymmetrySpec::load(kYamlData + "/twin_arm_spec.yaml");
  const TaskFactory f(task::taskCatalog(), "twin_arm_yaml", spec, YAML::Load(kTwinArmEnv));
  SymmetryVerifierOptions opt;
  opt.num_states = 6;
  opt.diagnosis_states = 2;
  const SymmetryReport r = verifySymmetry(f, opt);
  EXPECT_TRUE(r.passed()) << r.summary(8);

  // Under a mirror a world angular velocity is axial: declared a polar vector3, it is refused.
  YAML::Node root = YAML::LoadFile(kYamlData + "/twin_arm_spec.yaml");
  for (auto e : root["observation"]["central"])
    if (e["name"].as<std::string>() == "ball_ang_vel") e["kind"] = "vector3";
  YAML::Emitter out;
  out << root;
  const auto polar = sym::SymmetrySpec::parseString(out.c_str(), "polar_ball.yaml");
  try {
    TaskFactory bad(task::taskCatalog(), "twin_arm_yaml", polar, YAML::Load(kTwinArmEnv));
    ADD_FAILURE() << "a polar angular velocity was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("a world angular velocity ('ball_ang_vel') transforms under the mirror with "
                                         "normal y as kind 'axial3', not as the kind 'vector3'"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace masa::task
