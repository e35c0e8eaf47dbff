// masa_sac's policies as common policy files (learner/sac/sac_policy_file.hpp, format version 2
// with the tanh squash): read back, the file acts as the SAC policy's own tanh(mean) for the four
// methods, with and without the observation normalizer; a MASA file stays equivariant and passes
// the load-time check, an SA one does not; a flipped bit anywhere is refused; the ONNX export ends
// in a Tanh and matches; masa_deploy's runner commands the task's targets for tanh(mean); sampling
// a squashed file is refused; and PPO files (the shipped ones,
// format 1) load and act with their mean as before, and are still written as format 1.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <unistd.h>

#include "common/config/run_config.hpp"
#include "common/onnx/policy_onnx.hpp"
#include "common/policy/policy_file.hpp"
#include "common/sim/policy_evaluator.hpp"
#include "deploy/runner/deploy_config.hpp"
#include "deploy/runner/policy_runner.hpp"
#include "file_mutations.hpp"
#include "common/config/sac_config.hpp"
#include "common/model/sac_policy.hpp"
#include "learner/sac/sac_policy_file.hpp"
#include "robot_state_message.hpp"
#include "tasks/tasks.hpp"

namespace masa::sac {
namespace {

namespace fs = std::filesystem;
using model::Method;

fs::path sacTempFile(const std::string& name) {
  return fs::temp_directory_path() / ("masa_test_sac_policy_" + name + "_" + std::to_string(::getpid()));
}

std::string policyFileBytes(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Uniform in [lo, hi), from a generator seeded here.
Mat<float> uniformMat(int rows, int cols, float lo, float hi, uint64_t seed) {
  Rng rng(seed);
  std::uniform_real_distribution<float> u(lo, hi);
  Mat<float> m(rows, cols);
  for (int c = 0; c < cols; ++c)
    for (int r = 0; r < rows; ++r) m(r, c) = u(rng);
  return m;
}

config::RunConfig sacConfig(const std::string& task, const std::string& method) {
  return config::loadRunConfig(config::defaultConfigsDir(), {"task=" + task, "method=" + method,
                                                             "sac.policy_hidden=[16, 12]", "env.max_episode_steps=30"});
}

// A SAC policy as masa_sac builds it (sac_run.cpp), with a large last layer (means beyond
// tanh's linear range) and, when `normalizes`, a normalizer fitted off-centre.
struct SacSetup {
  config::RunConfig rc;
  SacConfig sc;
  sym::SymmetrySpec spec;
  SacPolicy<float> policy;

  static SacPolicyShape shapeOf(const config::RunConfig& rc, const SacConfig& sc) {
    SacPolicyShape s;
    s.method = rc.method;
    s.hidden = sc.policy_hidden;
    s.activation = rc.model.activation;
    s.log_std_min = sc.log_std_min;
    s.log_std_max = sc.log_std_max;
    return s;
  }
  SacSetup(const std::string& task, const std::string& method, bool normalizes, uint64_t seed)
      : rc(sacConfig(task, method)),
        sc(readSacConfig(rc)),
        spec(sym::SymmetrySpec::load(rc.spec_path)),
        policy(spec, shapeOf(rc, sc)) {
    Rng rng(seed);
    policy.initialize(rng, 4.0f);
    if (normalizes) {
      const int o = spec.obsDim();
      policy.obsNormalizer().update(uniformMat(o, 256, -2.3f, 3.7f, seed + 100));
      policy.setNormalizes(true);
    }
  }
  policy::LoadedPolicy saveAndLoad(const std::string& name) {
    const fs::path f = sacTempFile(name);
    saveSacPolicyFile(f.string(), rc, sc, policy, spec);
    policy::LoadedPolicy p = policy::loadPolicyFile(f.string());
    fs::remove(f);
    return p;
  }
  Mat<float> observations(int n, uint64_t seed) const { return uniformMat(spec.obsDim(), n, -2.0f, 2.0f, seed); }
  Mat<float> deterministic(const Mat<float>& obs) {
    Mat<float> a(spec.actDim(), obs.cols());
    policy.actDeterministic(obs, a);
    return a;
  }
};

TEST(SacPolicyFile, ReadBackItActsAsTheSacPoliciesTanhMeanForEveryMethod) {
  for (const char* method : {"masa", "sa", "sasa", "ma"})
    for (bool normalizes : {true, false}) {
      SCOPED_TRACE(std::string(method) + (normalizes ? " normalized" : " raw"));
      SacSetup s("a1_beam", method, normalizes, 11);
      policy::LoadedPolicy p = s.saveAndLoad(std::string(method) + (normalizes ? "_n" : "_r"));
      EXPECT_EQ(p.model->config().squash, model::ActionSquash::kTanh);
      EXPECT_EQ(p.config.method, s.rc.method);
      EXPECT_EQ(p.config.model.policy_hidden, (std::vector<int>{16, 12}));
      EXPECT_EQ(p.config.model.normalize_obs, normalizes);
      const Mat<float> obs = s.observations(40, 5);
      const Mat<float> want = s.deterministic(obs);
      // As a batch and one observation at a time (how the evaluator and the robot runner call it).
      const Mat<float> batch = p.model->actMean(obs);
      EXPECT_LE((batch - want).cwiseAbs().maxCoeff(), 1e-6f);
      for (int b = 0; b < obs.cols(); ++b) {
        const Mat<float> one = p.model->actMean(obs.col(b));
        ASSERT_LE((one - want.col(b)).cwiseAbs().maxCoeff(), 1e-6f) << "observation " << b;
      }
      // The squash is what makes them agree: the means reach well beyond tanh's linear range.
      p.model->forward(obs);
      const Mat<float> mean = p.model->mean();
      EXPECT_GT(mean.cwiseAbs().maxCoeff(), 1.0f);
      EXPECT_LE((mean.array().tanh().matrix() - want).cwiseAbs().maxCoeff(), 1e-6f);
    }
}

TEST(SacPolicyFile, TheSameOnAC4TaskAndItsCriticIsAZeroPlaceholder) {
  SacSetup s("ant_acrobatic", "masa", true, 12);
  policy::LoadedPolicy p = s.saveAndLoad("c4");
  const Mat<float> obs = s.observations(16, 6);
  EXPECT_LE((p.model->actMean(obs) - s.deterministic(obs)).cwiseAbs().maxCoeff(), 1e-6f);
  EXPECT_EQ(p.model->criticValue(obs).cwiseAbs().maxCoeff(), 0.0f);
  EXPECT_EQ(p.config.model.critic_hidden, std::vector<int>{1});
}

// max over i of |a(T_i o) - T_i a(o)| / (1 + |T_i a(o)|) on the loaded file's actions.
double loadedActionSymmetry(policy::LoadedPolicy& p, const Mat<float>& obs) {
  const auto& spec = p.spec;
  const Mat<float> act = p.model->actMean(obs);
  Mat<float> tobs(obs.rows(), obs.cols()), want(act.rows(), act.cols());
  double worst = 0;
  for (int i = 1; i < spec.numAgents(); ++i) {
    spec.obsTransform(i).apply<float>(obs, tobs);
    spec.actTransform(i).apply<float>(act, want);
    const Mat<float> got = p.model->actMean(tobs);
    worst = std::max(worst, static_cast<double>(((got - want).array().abs() / (1 + want.array().abs())).maxCoeff()));
  }
  return worst;
}

TEST(SacPolicyFile, AMasaFileIsEquivariantAndPassesTheLoadCheckAndAnSaFileIsNot) {
  for (const char* task : {"a1_beam", "ant_acrobatic"}) {
    SCOPED_TRACE(task);
    SacSetup masa(task, "masa", true, 13);
    policy::LoadedPolicy pm = masa.saveAndLoad("eq_masa");
    EXPECT_LT(policy::checkPolicySymmetry(pm, 1e-5), 1e-5);
    EXPECT_LT(loadedActionSymmetry(pm, masa.observations(24, 7)), 1e-5);
    SacSetup sa(task, "sa", true, 13);
    policy::LoadedPolicy ps = sa.saveAndLoad("eq_sa");
    EXPECT_GT(loadedActionSymmetry(ps, sa.observations(24, 7)), 1e-3);
  }
}

// The seal's payload starts after its 52-byte header and the kind's name (test_file_integrity.cpp).
uint32_t formatVersion(const std::string& sealed) {
  const std::size_t at = 52 + 4 + policy::kPolicyFileKind.name.size();
  EXPECT_EQ(sealed.compare(at, 8, "MASAPOL1"), 0);
  uint32_t v = 0;
  std::memcpy(&v, sealed.data() + at + 8, sizeof v);
  return v;
}

TEST(SacPolicyFile, SquashedFilesAreFormat2AndPpoFilesStayFormat1) {
  SacSetup s("a1_beam", "sa", true, 14);
  const fs::path sac = sacTempFile("format_sac"), ppo = sacTempFile("format_ppo");
  saveSacPolicyFile(sac.string(), s.rc, s.sc, s.policy, s.spec);
  EXPECT_EQ(formatVersion(policyFileBytes(sac)), 2u);
  const config::RunConfig rc = config::loadRunConfig(config::defaultConfigsDir(),
                                                     {"task=a1_beam", "model.policy_hidden=[8]", "model.critic_hidden=[8]"});
  model::ActorCritic<float> m(s.spec, rc.model);
  Rng rng(1);
  m.initialize(rng);
  policy::savePolicyFile(ppo.string(), rc, m);
  EXPECT_EQ(formatVersion(policyFileBytes(ppo)), 1u);
  EXPECT_EQ(formatVersion(policyFileBytes(fs::path(MASA_SOURCE_DIR) / "tasks/a1_beam/policy/policy.bin")), 1u);
  EXPECT_EQ(policy::loadPolicyFile(ppo.string()).model->config().squash, model::ActionSquash::kNone);
  fs::remove(sac);
  fs::remove(ppo);
}

TEST(SacPolicyFile, EveryShippedPpoPolicyStillLoadsAndActsWithItsUnsquashedMean) {
  int checked = 0;
  for (const auto& dir : fs::directory_iterator(fs::path(MASA_SOURCE_DIR) / "tasks")) {
    const fs::path f = dir.path() / "policy/policy.bin";
    if (!fs::exists(f)) continue;
    SCOPED_TRACE(f.string());
    policy::LoadedPolicy p = policy::loadPolicyFile(f.string());
    EXPECT_EQ(p.model->config().squash, model::ActionSquash::kNone);
    const auto& norm = p.model->obsNormalizer();
    Mat<float> obs(p.model->obsDim(), 16);
    const Mat<float> z = uniformMat(p.model->obsDim(), 16, -2.0f, 2.0f, 3);
    for (int b = 0; b < 16; ++b)
      for (int d = 0; d < obs.rows(); ++d)
        obs(d, b) = static_cast<float>(norm.mean()(d) + std::sqrt(norm.var()(d)) * z(d, b));
    const Mat<float> act = p.model->actMean(obs);
    p.model->forward(obs);
    EXPECT_EQ((act - p.model->mean()).cwiseAbs().maxCoeff(), 0.0f);
    ++checked;
  }
  EXPECT_GE(checked, 3);
}

TEST(SacPolicyFile, ABitFlippedAtAnyByteIsRefusedNamingTheFile) {
  SacSetup s("a1_beam", "masa", true, 15);
  const fs::path good = sacTempFile("flip_good"), bad = sacTempFile("flip_bad");
  saveSacPolicyFile(good.string(), s.rc, s.sc, s.policy, s.spec);
  const std::string bytes = policyFileBytes(good);
  ASSERT_NO_THROW(policy::loadPolicyFile(good.string()));
  {
    std::ofstream(bad, std::ios::binary) << bytes;
  }
  for (std::size_t i = 0; i < bytes.size(); i += (i < 1024 || i + 1024 > bytes.size()) ? 1 : 97) {
    fuzz::flipBitInFile(bad.string(), i);
    try {
      policy::loadPolicyFile(bad.string());
      ADD_FAILURE() << "a SAC policy file with byte " << i << " of " << bytes.size() << " flipped was loaded";
      break;
    } catch (const std::exception& e) {
      ASSERT_EQ(std::string(e.what()).rfind(bad.string() + ": ", 0), 0u) << e.what();
    }
    fuzz::flipBitInFile(bad.string(), i);
  }
  fs::remove(good);
  fs::remove(bad);
}

TEST(SacPolicyFile, TheOnnxExportEndsInATanhThatMakesActionMean) {
  SacSetup s("a1_beam", "masa", true, 16);
  policy::LoadedPolicy p = s.saveAndLoad("onnx");
  const onnx::ModelProto m = onnx_export::buildPolicyOnnx(p);
  const auto& nodes = m.graph().node();
  ASSERT_GT(nodes.size(), 1);
  const onnx::NodeProto* last_action = nullptr;
  for (const auto& n : nodes)
    if (n.output_size() > 0 && n.output(0) == "action_mean") last_action = &n;
  ASSERT_NE(last_action, nullptr);
  EXPECT_EQ(last_action->op_type(), "Tanh");
  EXPECT_EQ(last_action->input(0), "action_before_tanh");
  std::string squash;
  for (const auto& e : m.metadata_props())
    if (e.key() == "action_squash") squash = e.value();
  EXPECT_EQ(squash, "tanh");
  // A PPO file's action_mean comes out of the output maps' MatMul, metadata "none".
  policy::LoadedPolicy ppo = policy::loadPolicyFile(std::string(MASA_SOURCE_DIR) + "/tasks/a1_beam/policy/policy.bin");
  const onnx::ModelProto mp = onnx_export::buildPolicyOnnx(ppo);
  for (const auto& n : mp.graph().node()) {
    if (n.output_size() > 0 && n.output(0) == "action_mean") {
      EXPECT_NE(n.op_type(), "Tanh");
    }
  }
  std::string ppo_squash;
  for (const auto& e : mp.metadata_props())
    if (e.key() == "action_squash") ppo_squash = e.value();
  EXPECT_EQ(ppo_squash, "none");
}

// The runner's first policy command, from a robot that stands still, against the task's joint
// targets for the SAC policy's own tanh(mean) of the observation the task makes of that state
// (last action zero), the limits the runner keeps applied; rates and clips wide enough not to bind.
TEST(SacPolicyFile, TheDeployRunnerCommandsTheTasksTargetsForTanhOfTheMean) {
  SacSetup s("a1_beam", "masa", true, 19);
  const fs::path f = sacTempFile("deploy");
  saveSacPolicyFile(f.string(), s.rc, s.sc, s.policy, s.spec);
  policy::LoadedPolicy lp = policy::loadPolicyFile(f.string());
  fs::remove(f);
  task::TaskFactory factory{task::taskCatalog(), lp.config.task, lp.spec, lp.config.env, lp.config.origin, lp.source};
  std::unique_ptr<task::Task> sim = factory.create(), robot_side = factory.create();
  Rng rng(0);
  sim->reset(rng);
  deploy::DeployConfig c = deploy::loadDeployConfig("");
  c.calibration_settle_s = 0;
  c.calibration_max_rate = 1e3;
  c.max_target_rate = 1e6;
  c.action_clip = 3.0;
  c.position_margin = 0;
  deploy::PolicyRunner r(lp, c, 1);
  masa::lcmt_robot_command cmd = r.makeCommand();
  masa::lcmt_robot_state state{};
  bool policy_command = false;
  for (int64_t t = 0, utime = 0; t < 200000 && !policy_command; t += 100) {
    if (t % 5000 == 0) r.onState(state = test::stateOf(*sim, ++utime), t);
    policy_command = r.poll(t, cmd) && cmd.mode == static_cast<int>(deploy::Mode::kPolicy);
  }
  ASSERT_TRUE(policy_command) << r.reason();
  const int n = sim->actDim();
  const double base[13] = {state.base_x,  state.base_y,  state.base_z,  state.base_qw, state.base_qx,
                           state.base_qy, state.base_qz, state.base_vx, state.base_vy, state.base_vz,
                           state.base_wx, state.base_wy, state.base_wz};
  const std::vector<double> zero(n, 0.0);
  robot_side->setMeasuredState(state.joint_position.data(), state.joint_velocity.data(), base, base + 7, zero.data());
  Mat<float> obs(sim->obsDim(), 1);
  robot_side->observe(obs.data());
  const Mat<float> action = s.deterministic(obs);
  const auto targetsOf = [&](const Mat<float>& a) {
    std::vector<double> ad(a.data(), a.data() + n), pos(n), vel(n), tau(n), kp(n), kd(n);
    EXPECT_TRUE(robot_side->jointCommand(ad.data(), pos.data(), vel.data(), tau.data(), kp.data(), kd.data()));
    for (int k = 0; k < n; ++k) pos[k] = std::clamp(pos[k], r.lowerLimit()[k], r.upperLimit()[k]);
    return pos;
  };
  const std::vector<double> want = targetsOf(action);
  for (int k = 0; k < n; ++k) EXPECT_NEAR(cmd.position[k], want[k], 1e-5) << "joint " << k;
  // Without the squash the command would differ: the mean reaches beyond tanh's linear range.
  Mat<float> obs_n;
  s.policy.normalize(obs, obs_n);
  s.policy.forward(obs_n);
  const std::vector<double> plain = targetsOf(s.policy.mean());
  double apart = 0;
  for (int k = 0; k < n; ++k) apart = std::max(apart, std::abs(plain[k] - want[k]));
  EXPECT_GT(apart, 1e-3);
}

TEST(SacPolicyFile, SamplingASquashedFileIsRefusedAndItsMeanEvaluates) {
  SacSetup s("a1_beam", "masa", true, 17);
  policy::LoadedPolicy p = s.saveAndLoad("sample");
  task::TaskFactory factory(task::taskCatalog(), p.config.task, p.spec, p.config.env, p.config.origin);
  task::PolicyEvaluator evaluator(factory, *p.model);
  task::EvalOptions o;
  o.episodes = 1;
  o.deterministic = false;
  try {
    evaluator.run(o);
    FAIL() << "a squashed policy was sampled";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("cannot be sampled"), std::string::npos) << e.what();
  }
  o.deterministic = true;
  EXPECT_EQ(evaluator.run(o).episodes.size(), 1u);
}

TEST(SacPolicyFile, APpoModelLoadedFromASquashedFileCannotBeTrained) {
  SacSetup s("a1_beam", "sa", true, 18);
  policy::LoadedPolicy p = s.saveAndLoad("train");
  const Mat<float> obs = s.observations(4, 8);
  p.model->forward(obs);
  const Mat<float> dmean = Mat<float>::Zero(p.model->actDim(), 4), dvalue = Mat<float>::Zero(1, 4);
  const Vec<float> dlog_std = Vec<float>::Zero(p.model->actDim());
  EXPECT_ANY_THROW(p.model->backward(dmean, dlog_std, dvalue));
}

}  // namespace
}  // namespace masa::sac
