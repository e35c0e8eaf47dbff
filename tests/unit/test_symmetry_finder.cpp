// The symmetry finder (issue #13 item 2): from a model alone it proposes the symmetry every shipped
// robot ships with (same group, same action of the group on the actuators, limbs in any order), the
// physics verifier confirms it, and a model without symmetry gets no confirmed candidate.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>

#include "common/physics_symmetry/found_spec_writer.hpp"
#include "common/physics_symmetry/joint_slot_names.hpp"
#include "common/physics_symmetry/symmetry_candidate_check.hpp"
#include "common/physics_symmetry/symmetry_finder.hpp"
#include "task_test_support.hpp"
#include "tasks/tasks.hpp"

namespace masa::task {
namespace {

using namespace masa::test;

const std::string kFinderData = MASA_TEST_DATA_DIR;
const std::string kFinderSource = MASA_SOURCE_DIR;

std::string writeTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

std::string withReplaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// The actuator each action dimension drives: the binding names an actuator, or the joint it drives.
std::vector<int> actuatorOfAction(const sym::SymmetrySpec& spec, const mjModel* m) {
  std::vector<int> out;
  for (const auto& name : spec.actuatorsInActionOrder()) {
    int a = mj_name2id(m, mjOBJ_ACTUATOR, name.c_str());
    if (a < 0) {
      const int j = mj_name2id(m, mjOBJ_JOINT, name.c_str());
      for (int k = 0; k < m->nu; ++k)
        if (m->actuator_trnid[2 * k] == j) a = k;
    }
    EXPECT_GE(a, 0) << name;
    out.push_back(a);
  }
  return out;
}

// T_i as a map between actuators: actuator r receives sign x actuator c. Independent of the order of
// the limbs, of the slots inside a limb and of the entry names: what is left is the group's action.
using ActuatorMap = std::map<int, std::pair<int, double>>;
ActuatorMap actuatorMap(const sym::SymmetrySpec& spec, const mjModel* m, int i) {
  const auto act = actuatorOfAction(spec, m);
  const sym::SparseMap& t = spec.actTransform(i);
  ActuatorMap out;
  for (int r = 0; r < t.rows(); ++r) {
    EXPECT_EQ(t.rowStart()[r + 1] - t.rowStart()[r], 1) << "row " << r << " of T_" << i << " is not a signed permutation";
    const int k = t.rowStart()[r];
    out[act[r]] = {act[t.colIndex()[k]], t.values()[k]};
  }
  return out;
}

const SymmetryCandidate* candidateWithGroup(const FoundSymmetries& found, const sym::Group& g) {
  for (const auto* c : found.proposed())
    if (c->group.type == g.type && c->group.axis == g.axis && c->group.order == g.order) return c;
  return nullptr;
}

sym::SymmetrySpec specOf(const FoundSymmetries& found, const SymmetryCandidate& c) {
  return sym::SymmetrySpec::parseString(foundSpecYaml(found, c), "found");
}

// The found spec acts on the actuators as the shipped one does, moves the same free joints the
// same way, and keeps the same joints central.
void expectSameGroupAction(const sym::SymmetrySpec& found, const sym::SymmetrySpec& shipped, const mjModel* m) {
  ASSERT_EQ(found.numAgents(), shipped.numAgents());
  ASSERT_EQ(found.actDim(), shipped.actDim());
  EXPECT_EQ(found.actCentralDim(), shipped.actCentralDim());
  for (int i = 0; i < shipped.numAgents(); ++i)
    EXPECT_EQ(actuatorMap(found, m, i), actuatorMap(shipped, m, i)) << "T_" << i << " differs on the actuators";
  std::map<std::string, sym::FreeJointKind> a, b;
  for (const auto& f : found.mujoco().free_joints) a[f.name] = f.kind;
  for (const auto& f : shipped.mujoco().free_joints) b[f.name] = f.kind;
  EXPECT_EQ(a, b) << "free joints or their kinds differ";
}

class ShippedRobot : public ::testing::TestWithParam<std::string> {};

TEST_P(ShippedRobot, FinderProposesTheShippedSymmetryAndThePhysicsConfirmsIt) {
  const std::string task = GetParam();
  const std::string model_file = kFinderSource + "/tasks/" + task + "/model.xml";
  const auto shipped = shippedSpec(task);
  const auto found = findSymmetries(model_file);
  const SymmetryCandidate* c = candidateWithGroup(found, shipped.group());
  ASSERT_NE(c, nullptr) << "the shipped group is not among the proposals";
  EXPECT_EQ(found.proposed().front(), c) << "the shipped group is not the best proposal";
  const auto model = MujocoModel::load(model_file);
  expectSameGroupAction(specOf(found, *c), shipped, model->get());

  const CandidateCheck check = checkCandidate(found, *c, {.num_states = 5});
  EXPECT_EQ(check.error, "");
  EXPECT_TRUE(check.confirmed) << check.report.summary();
}

INSTANTIATE_TEST_SUITE_P(SymmetryFinder, ShippedRobot,
                         ::testing::Values("a1_beam", "ant_acrobatic", "trifinger_lift", "humanoid_tightrope",
                                           "humanoid_dribbling"));

// Every other group the geometry proposes for a shipped robot is one the physics confirms too (the
// ant's two mirrors); a group it refutes is not proposed.
TEST(SymmetryFinder, EveryProposalForTheShippedAntIsConfirmed) {
  const auto found = findSymmetries(kFinderSource + "/tasks/ant_acrobatic/model.xml");
  ASSERT_EQ(found.proposed().size(), 3u);
  for (const auto* c : found.proposed()) EXPECT_TRUE(checkCandidate(found, *c, {.num_states = 3}).confirmed) << c->label;
}

// The C4 walker's actuators have no names: the binding names their joints. The whole proposed
// spec, observation included, is the one the walker's YAML task ships with, but for the heading
// (task state the model does not show).
TEST(SymmetryFinder, ProposesC4ForTheWalkerWithUnnamedActuatorsAndItsYamlTaskObservation) {
  const auto found = findSymmetries(kFinderData + "/c4_walker.xml");
  ASSERT_FALSE(found.proposed().empty());
  const SymmetryCandidate& best = *found.proposed().front();
  EXPECT_EQ(best.label, "rotation C4 about z");
  ASSERT_EQ(best.limb.size(), 2u);
  EXPECT_EQ(best.limb[0].binding, (std::vector<std::string>{"hip0", "hip1", "hip2", "hip3"}));
  EXPECT_EQ(best.limb[1].binding, (std::vector<std::string>{"knee0", "knee1", "knee2", "knee3"}));

  const auto spec = specOf(found, best);
  const auto shipped = shippedSpec("c4_walker");
  const auto model = MujocoModel::load(kFinderData + "/c4_walker.xml");
  expectSameGroupAction(spec, shipped, model->get());
  // Observation: the same dimensions by name, and the same T_i between them.
  std::map<std::string, int> shipped_dim;
  for (int d = 0; d < shipped.obsDim(); ++d) shipped_dim[shipped.obsNames()[d]] = d;
  std::vector<std::string> missing;
  for (const auto& [name, d] : shipped_dim)
    if (std::find(spec.obsNames().begin(), spec.obsNames().end(), name) == spec.obsNames().end()) missing.push_back(name);
  EXPECT_EQ(missing, (std::vector<std::string>{"central.heading[0]", "central.heading[1]"}));
  ASSERT_EQ(spec.obsDim() + 2, shipped.obsDim());
  for (int i = 0; i < 4; ++i) {
    const Eigen::MatrixXd a = spec.obsTransform(i).toDense(), b = shipped.obsTransform(i).toDense();
    for (int r = 0; r < spec.obsDim(); ++r)
      for (int col = 0; col < spec.obsDim(); ++col)
        EXPECT_EQ(a(r, col), b(shipped_dim[spec.obsNames()[r]], shipped_dim[spec.obsNames()[col]]))
            << "T_" << i << " at " << spec.obsNames()[r] << " <- " << spec.obsNames()[col];
  }
  const CandidateCheck check = checkCandidate(found, best, {.num_states = 5});
  EXPECT_TRUE(check.confirmed) << check.error << check.report.summary();
}

// What --task-out writes is a task config: its env builds the YAML task over the spec --out writes.
TEST(SymmetryFinder, TheWrittenTaskConfigBuildsAYamlTaskOverTheWrittenSpec) {
  const auto found = findSymmetries(kFinderSource + "/tasks/humanoid_tightrope/model.xml");
  const SymmetryCandidate& best = *found.proposed().front();
  const std::string spec_path = writeTemp("found_humanoid.yaml", foundSpecYaml(found, best));
  const YAML::Node config = YAML::Load(foundTaskYaml(found, best, spec_path));
  EXPECT_EQ(config["spec"].as<std::string>(), spec_path);
  EXPECT_EQ(config["env"]["task_code"].as<std::string>(), "yaml");
  const auto spec = sym::SymmetrySpec::load(spec_path);
  const TaskFactory factory(task::taskCatalog(), "found_humanoid", spec, config["env"], {}, "test");
  const auto t = factory.create();
  // The base (height, velocities, quaternion: 11), the abdomen (9) and 2 limbs of 27, as the shipped humanoid.
  EXPECT_EQ(t->obsDim(), 1 + 3 + 3 + 1 + 3 + 9 + 2 * 27);
  EXPECT_EQ(spec.actDim(), 21);
}

// Legs at irregular angles: no mirror, no rotation maps the joints onto each other.
const char* kLopsidedModel = R"(<mujoco model="lopsided">
  <worldbody>
    <geom type="plane" size="5 5 0.1"/>
    <body name="torso" pos="0 0 0.4">
      <freejoint name="root"/>
      <geom type="sphere" size="0.1"/>
      <body name="leg_a" pos="0.1 0 0"><joint name="hip_a" axis="0 0 1"/><geom type="capsule" fromto="0 0 0 0.3 0 -0.3" size="0.03"/></body>
      <body name="leg_b" pos="-0.02 0.1 0" euler="0 0 100"><joint name="hip_b" axis="0 0 1"/><geom type="capsule" fromto="0 0 0 0.3 0 -0.3" size="0.03"/></body>
      <body name="leg_c" pos="-0.06 -0.08 0" euler="0 0 230"><joint name="hip_c" axis="0 0 1"/><geom type="capsule" fromto="0 0 0 0.25 0 -0.3" size="0.03"/></body>
    </body>
  </worldbody>
  <actuator><motor joint="hip_a"/><motor joint="hip_b"/><motor joint="hip_c"/></actuator>
</mujoco>)";

TEST(SymmetryFinder, AModelWithoutSymmetryGetsNoProposal) {
  const auto found = findSymmetries(writeTemp("lopsided.xml", kLopsidedModel));
  EXPECT_TRUE(found.proposed().empty());
  ASSERT_EQ(found.candidates.size(), 6u);
  for (const auto& c : found.candidates) EXPECT_FALSE(c.reason.empty()) << c.label;
}

// What the geometry cannot see, the physics refutes: one hip's motor twice as strong leaves every
// joint where the symmetry wants it, so C4 and both mirrors are proposed, and none is confirmed.
TEST(SymmetryFinder, AStrongerMotorOnOneLegLeavesNoConfirmedCandidate) {
  const std::string xml = withReplaced(readTextFile(kFinderData + "/c4_walker.xml"), R"(<motor joint="hip2"/>)",
                                   R"(<motor joint="hip2" gear="40"/>)");
  const auto found = findSymmetries(writeTemp("walker_strong_hip.xml", xml));
  ASSERT_EQ(found.proposed().size(), 3u);
  for (const auto* c : found.proposed()) {
    const CandidateCheck check = checkCandidate(found, *c, {.num_states = 3});
    EXPECT_FALSE(check.confirmed) << c->label;
    ASSERT_TRUE(check.report.parts.culprit.has_value()) << c->label;
    EXPECT_EQ(check.report.parts.culprit->part, "actuation") << c->label;
  }
}

// A joint reversed in one leg is found as a sign (limb_signs), and the physics agrees.
TEST(SymmetryFinder, AReversedKneeAxisBecomesALimbSign) {
  std::string xml = readTextFile(kFinderData + "/c4_walker.xml");
  xml = withReplaced(xml, R"(<joint name="knee1" type="hinge" axis="0 1 0" range="-30 70"/>)",
                 R"(<joint name="knee1" type="hinge" axis="0 -1 0" range="-70 30"/>)");
  const auto found = findSymmetries(writeTemp("walker_reversed_knee.xml", xml));
  ASSERT_FALSE(found.proposed().empty());
  const SymmetryCandidate& c4 = *found.proposed().front();
  EXPECT_EQ(c4.label, "rotation C4 about z");
  ASSERT_EQ(c4.limb.size(), 2u);
  EXPECT_EQ(c4.limb[1].limb_signs, (std::vector<int>{1, -1, 1, 1}));
  EXPECT_TRUE(checkCandidate(found, c4, {.num_states = 3}).confirmed);
}

TEST(SymmetryFinder, BadInputIsRefusedWithTheFileAndTheReason) {
  auto message = [](const std::string& path) {
    try {
      findSymmetries(path);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string missing = ::testing::TempDir() + "/no_such_robot.xml";
  EXPECT_EQ(message(missing), missing + ": model file not found");
  const std::string broken = writeTemp("broken.xml", "<mujoco><worldbody><body name=\"a\"></worldbody></mujoco>");
  EXPECT_NE(message(broken).find(broken + ": MuJoCo could not load the model"), std::string::npos) << message(broken);
  const std::string passive = writeTemp(
      "passive.xml", withReplaced(readTextFile(kFinderData + "/c4_walker.xml"), R"(<motor joint="knee3"/>)", ""));
  EXPECT_EQ(message(passive), passive +
                                  ": joint 'knee3' has no actuator: the spec moves each hinge and slide with the action "
                                  "of the actuator that drives it");
}

TEST(JointSlotNames, DropWhatDiffersBetweenLimbs) {
  EXPECT_EQ(slotNames({{"right_hip_x", "left_hip_x"}, {"abdomen_z"}}),
            (std::vector<std::string>{"hip_x", "abdomen_z"}));
  EXPECT_EQ(slotNames({{"hip0", "hip1"}, {"knee0", "knee1"}}), (std::vector<std::string>{"hip", "knee"}));
  EXPECT_EQ(slotNames({{"FR_hip", "FL_hip"}, {"RR_hip", "RL_hip"}}), (std::vector<std::string>{"F_hip", "R_hip"}));
  EXPECT_EQ(slotNames({{"finger0_upper", "finger1_upper", "finger2_upper"}}), (std::vector<std::string>{"upper"}));
  EXPECT_EQ(slotNames({{"a", "b"}, {"c", "d"}}), (std::vector<std::string>{"a", "c"}));
  EXPECT_EQ(sideOfName("right_knee"), 1);
  EXPECT_EQ(sideOfName("FL_calf"), -1);
  EXPECT_EQ(sideOfName("L_hip"), -1);
  EXPECT_EQ(sideOfName("hip_0"), 0);
  EXPECT_EQ(limbNumbers({"hip_2", "hip_0", "hip_1"}), (std::vector<int>{2, 0, 1}));
  EXPECT_EQ(limbNumbers({"leg1_hip2", "leg2_hip2"}), (std::vector<int>{1, 2}));
  EXPECT_FALSE(limbNumbers({"right_shoulder1", "left_shoulder1"}).has_value());
  EXPECT_EQ(identifier("3rd-joint"), "j3rd_joint");
}

}  // namespace
}  // namespace masa::task
