// The verifier names the culprit (issue #13 item 3): each kind of break, on the C4 walker written
// for the test (tests/data/c4_walker.xml, unnamed actuators bound by joint name) and on a shipped
// robot, is named at the right joint with the right kind of fix, while the step alone spreads the
// error over every joint.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>

#include "common/physics_symmetry/imperfection_report.hpp"
#include "task_test_support.hpp"

namespace masa::task {
namespace {

using namespace masa::test;

const std::string kData = MASA_TEST_DATA_DIR;

std::string walkerSpecText() { return readTextFile(kData + "/c4_walker_spec.yaml"); }

// The user's path: the "mjcf" task over a model file and a spec.
TaskFactory walker(const std::string& spec_text, const std::string& model_file = kData + "/c4_walker.xml") {
  YAML::Node env;
  env["model_file"] = model_file;
  return TaskFactory(taskCatalog(), "mjcf", sym::SymmetrySpec::parseString(spec_text, "walker.yaml"), env, {}, "test");
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

SymmetryReport verify(const TaskFactory& f) { return verifySymmetry(f, {.num_states = 5}); }

TEST(SymmetryCulprit, TheCorrectWalkerSpecPassesWithActuatorsBoundByJointName) {
  const SymmetryReport r = verify(walker(walkerSpecText()));
  EXPECT_TRUE(r.passed()) << r.summary();
  EXPECT_FALSE(r.parts.culprit.has_value()) << r.summary();
  for (const PartCheck& p : r.parts.parts) EXPECT_LT(p.worst, 1e-9) << p.name;
}

TEST(SymmetryCulprit, OneFlippedHipSignIsNamedAtThatLegsHip) {
  const std::string text = replaced(walkerSpecText(), "{name: hip, kind: invariant}",
                                    "{name: hip, kind: invariant, limb_signs: [1, -1, 1, 1]}");
  const SymmetryReport r = verify(walker(text));
  ASSERT_FALSE(r.passed());
  // The step alone: every leg's joints are off, so the step does not name the hip.
  int joints_off = 0;
  for (const NamedError& e : r.joints) joints_off += e.error > 1e-3;
  EXPECT_GE(joints_off, 4) << r.summary();
  ASSERT_TRUE(r.parts.culprit) << r.summary();
  EXPECT_EQ(r.parts.culprit->joint, "hip1") << r.summary();
  EXPECT_EQ(r.parts.culprit->action, "limb1.hip");
  EXPECT_EQ(r.parts.culprit->fix, Fix::kSign);
  EXPECT_EQ(r.parts.culprit->part, "kinematics");
}

TEST(SymmetryCulprit, TwoSwappedLegsAreNamedAndTheTrueBindingIsProposed) {
  std::string text = replaced(walkerSpecText(), "[hip1, knee1]", "[hipX, kneeX]");
  text = replaced(text, "[hip2, knee2]", "[hip1, knee1]");
  text = replaced(text, "[hipX, kneeX]", "[hip2, knee2]");
  const SymmetryReport r = verify(walker(text));
  ASSERT_FALSE(r.passed());
  ASSERT_TRUE(r.parts.culprit) << r.summary();
  EXPECT_EQ(r.parts.culprit->fix, Fix::kPermutation);
  EXPECT_EQ(r.parts.culprit->joint, "hip2");  // bound as limb 1, where hip1 belongs
  EXPECT_EQ(r.parts.culprit->action, "limb1.hip");
  EXPECT_NE(r.parts.culprit->advice.find("'hip1'"), std::string::npos) << r.parts.culprit->advice;
  EXPECT_NE(r.parts.culprit->advice.find("[[hip0, knee0], [hip1, knee1], [hip2, knee2], [hip3, knee3]]"), std::string::npos)
      << r.parts.culprit->advice;
}

TEST(SymmetryCulprit, AWrongGroupAxisIsNamedWithTheAxisThatHolds) {
  const SymmetryReport r = verify(walker(replaced(walkerSpecText(), "axis: z", "axis: x")));
  ASSERT_FALSE(r.passed());
  ASSERT_TRUE(r.parts.culprit) << r.summary();
  EXPECT_EQ(r.parts.culprit->fix, Fix::kGroupAxis) << r.summary();
  EXPECT_EQ(r.parts.culprit->joint, "hip0");
  EXPECT_NE(r.parts.culprit->advice.find("group.axis: z"), std::string::npos) << r.parts.culprit->advice;
}

// Legs mounted on a rectangle: only the half turn maps the walker onto itself, so the C4 spec's
// group order is wrong.
TEST(SymmetryCulprit, AWrongGroupOrderIsNamedWithTheOrderThatHolds) {
  std::string model = readTextFile(kData + "/c4_walker.xml");
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{{"\"0.2 0.2 0\"", "\"0.3 0.15 0\""},
                                                                                {"\"-0.2 0.2 0\"", "\"-0.3 0.15 0\""},
                                                                                {"\"-0.2 -0.2 0\"", "\"-0.3 -0.15 0\""},
                                                                                {"\"0.2 -0.2 0\"", "\"0.3 -0.15 0\""}})
    model = replaced(model, from, to);
  const std::string path = std::filesystem::temp_directory_path() / "masa_rect_walker.xml";
  std::ofstream(path) << model;
  const SymmetryReport r = verify(walker(walkerSpecText(), path));
  ASSERT_FALSE(r.passed());
  ASSERT_TRUE(r.parts.culprit) << r.summary();
  EXPECT_EQ(r.parts.culprit->fix, Fix::kGroupOrder) << r.summary();
  EXPECT_EQ(r.parts.culprit->joint, "hip0");
  EXPECT_NE(r.parts.culprit->advice.find("looks like C2, not C4"), std::string::npos) << r.parts.culprit->advice;
}

// Limbs listed clockwise while T_1 turns counter-clockwise: the cycle's order is wrong.
TEST(SymmetryCulprit, LimbsListedAgainstTheRotationAreNamedAsAPermutation) {
  std::string text = replaced(walkerSpecText(), "[hip1, knee1]", "[hipX, kneeX]");
  text = replaced(text, "[hip3, knee3]", "[hip1, knee1]");
  text = replaced(text, "[hipX, kneeX]", "[hip3, knee3]");
  const SymmetryReport r = verify(walker(text));
  ASSERT_TRUE(r.parts.culprit) << r.summary();
  EXPECT_EQ(r.parts.culprit->fix, Fix::kPermutation);
  EXPECT_EQ(r.parts.culprit->joint, "hip3");
  EXPECT_EQ(r.parts.culprit->action, "limb1.hip");
}

// A shipped robot: the humanoid's ankle_x claimed mirror-invariant (it flips).
TEST(SymmetryCulprit, AFlippedSignOnTheShippedHumanoidIsNamedAtTheAnkle) {
  const auto broken = editedSpec("humanoid_tightrope", [](YAML::Node& root) {
    for (const char* block : {"observation", "action"})
      for (YAML::Node e : root[block]["limb"])
        if (e["name"].as<std::string>().rfind("ankle_x", 0) == 0) e["kind"] = "invariant";
  });
  const SymmetryReport r = verifySymmetry(envFactory("humanoid_tightrope", shippedEnv("humanoid_tightrope"), broken),
                                          {.num_states = 3});
  ASSERT_FALSE(r.passed());
  ASSERT_TRUE(r.parts.culprit) << r.summary();
  EXPECT_EQ(r.parts.culprit->fix, Fix::kSign);
  EXPECT_NE(r.parts.culprit->joint.find("ankle_x"), std::string::npos) << r.summary();
  EXPECT_EQ(r.parts.culprit->part, "kinematics");
}

// A shipped robot's limbs swapped inside one limb block: the A1's hip and thigh of limb 1.
TEST(SymmetryCulprit, SwappedSlotsOnTheShippedA1AreNamedAsAPermutation) {
  const auto broken = editedSpec("a1_beam", [](YAML::Node& root) {
    YAML::Node limb = root["mujoco"]["actuators"]["limbs"][1];
    const std::string first = limb[0].as<std::string>();
    limb[0] = limb[1].as<std::string>();
    limb[1] = first;
  });
  const SymmetryReport r = verifySymmetry(envFactory("a1_beam", shippedEnv("a1_beam"), broken), {.num_states = 3});
  ASSERT_TRUE(r.parts.culprit) << r.summary();
  EXPECT_EQ(r.parts.culprit->fix, Fix::kPermutation) << r.summary();
  EXPECT_EQ(r.parts.culprit->action.rfind("limb1.", 0), 0u) << r.summary();
}

TEST(SymmetryCulprit, ABindingNameThatIsNeitherActuatorNorJointIsNamed) {
  try {
    walker(replaced(walkerSpecText(), "[hip2, knee2]", "[hip2, kneee2]"));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no actuator or joint named 'kneee2'"), std::string::npos) << e.what();
  }
}

// Item 4: leg 2's shin twice as dense. The report names limb 2 and its mass (its inertia scales
// with it) and nothing else, and the step is no longer exact.
TEST(SymmetryImperfection, AHeavierLegIsNamedWithItsMassAndTheStepErrorIsReported) {
  const std::string model = replaced(readTextFile(kData + "/c4_walker.xml"),
                                     "<geom type=\"capsule\" fromto=\"0 0 0 0.1 0 -0.4\" size=\"0.04\"/>\n        </body>\n      </body>\n      <body name=\"leg3\"",
                                     "<geom type=\"capsule\" fromto=\"0 0 0 0.1 0 -0.4\" size=\"0.04\" density=\"1000\"/>\n        </body>\n      </body>\n      <body name=\"leg3\"");
  const std::string path = std::filesystem::temp_directory_path() / "masa_heavy_leg_walker.xml";
  std::ofstream(path) << model;
  const ImperfectionReport r = imperfectionReport(walker(walkerSpecText(), path), {.num_states = 3});
  ASSERT_FALSE(r.entries.empty()) << r.summary();
  bool mass = false;
  for (const Imperfection& e : r.entries) {
    if (e.relative < 1e-9) continue;
    EXPECT_EQ(e.limb, 2) << r.summary();
    EXPECT_EQ(e.joint, "knee2") << r.summary();  // shin2 is the body knee2 moves
    mass = mass || e.term == "mass";
  }
  EXPECT_TRUE(mass) << r.summary();
  EXPECT_EQ(r.entries.front().limb, 2);
  EXPECT_NEAR(r.entries.front().value / r.entries.front().mean, 2.0, 1e-9) << r.summary();
  EXPECT_FALSE(r.dynamics.passed());
  ASSERT_TRUE(r.dynamics.parts.culprit) << r.summary();
  EXPECT_EQ(r.dynamics.parts.culprit->part, "mass matrix") << r.summary();
  EXPECT_NE(r.summary().find("limb 2 (knee2): mass"), std::string::npos) << r.summary();
}

TEST(SymmetryImperfection, TheSymmetricWalkerHasNone) {
  const ImperfectionReport r = imperfectionReport(walker(walkerSpecText()), {.num_states = 2});
  EXPECT_TRUE(r.entries.empty()) << r.summary();
  EXPECT_TRUE(r.dynamics.passed());
}

}  // namespace
}  // namespace masa::task
