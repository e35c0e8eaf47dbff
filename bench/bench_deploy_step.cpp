// The policy runner's control step on one core, in-process (no LCM): PolicyRunner::onState with
// an A1 state, then poll() computing a policy command (task observation, policy mean, joint
// command, limits) with the shipped A1 Beam policy. bench/deploy_latency.sh measures the same
// step end to end over LCM at a 500 Hz state rate.
#include <benchmark/benchmark.h>

#include "common/policy/policy_file.hpp"
#include "deploy/runner/policy_runner.hpp"
#include "tasks/tasks.hpp"

namespace {

void BM_DeployPolicyCommand(benchmark::State& st) {
  using namespace masa;
  policy::LoadedPolicy lp = policy::loadPolicyFile(std::string(MASA_SOURCE_DIR) + "/tasks/a1_beam/policy/policy.bin");
  deploy::DeployConfig c = deploy::loadDeployConfig("");
  c.calibration_settle_s = 0;
  c.calibration_max_rate = 100;
  deploy::PolicyRunner r(lp, c, 1);
  task::TaskFactory factory(task::taskCatalog(), lp.config.task, lp.spec, lp.config.env, lp.config.origin, lp.source);
  auto sim = factory.create();
  Rng rng(0);
  sim->reset(rng);
  masa::lcmt_robot_state s{};
  s.num_joints = r.numJoints();
  for (int k = 0; k < r.numJoints(); ++k) {
    const int j = sim->jointOfAction(k);
    s.joint_position.push_back(sim->data()->qpos[sim->model()->jnt_qposadr[j]]);
    s.joint_velocity.push_back(0.0);
    s.joint_torque.push_back(0.0);
  }
  s.has_base = true;
  s.base_z = 0.4;
  s.base_qw = 1;
  masa::lcmt_robot_command cmd = r.makeCommand();
  int64_t t = 0;
  // Calibrate, then one command per period of simulated time.
  for (int i = 0; i < 10; ++i, t += 20000) {
    ++s.utime;
    r.onState(s, t);
    r.poll(t, cmd);
  }
  if (r.mode() != deploy::Mode::kPolicy) st.SkipWithError("the runner did not reach policy mode");
  for (auto _ : st) {
    t += 20000;
    ++s.utime;
    r.onState(s, t);
    benchmark::DoNotOptimize(r.poll(t, cmd));
  }
  st.counters["policy_steps"] = static_cast<double>(r.policySteps());
}
BENCHMARK(BM_DeployPolicyCommand)->Unit(benchmark::kMicrosecond);

}  // namespace
