// "mjcf": a task with no task code, for checking the symmetry of a robot a user brings (an MJCF
// file and a spec with a `mujoco` section). It has no observation (zeros) and no reward: the
// physics verifier then checks the joints alone, which is what names a wrong sign or limb.
#include "common/sim/mjcf_task.hpp"

namespace masa::task {
namespace {

class MjcfTask : public Task {
 public:
  MjcfTask(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec, EnvParams& p)
      : Task("mjcf", std::move(model), spec, p, {}), noise_(p.number("reset_noise", 0.1)) {}

 protected:
  // Random joint angles and velocities around the model's reference pose; free joints keep their pose.
  void resetTask(Rng& rng) override {
    const mjModel* m = model();
    std::uniform_real_distribution<double> u(-noise_, noise_);
    for (int j = 0; j < m->njnt; ++j)
      if (m->jnt_type[j] == mjJNT_HINGE || m->jnt_type[j] == mjJNT_SLIDE) data_->qpos[m->jnt_qposadr[j]] += u(rng);
    for (int k = 0; k < m->nv; ++k) data_->qvel[k] = u(rng);
  }
  void writeObservation(float* out) const override { std::fill(out, out + obsDim(), 0.0f); }
  void computeRewardTerms(double*) const override {}
  bool isTerminated() const override { return false; }

 private:
  double noise_;
};

}  // namespace

// Listed in tasks/tasks.cpp (the programs pass that catalog in).
std::unique_ptr<Task> makeMjcf(std::shared_ptr<const MujocoModel> m, const sym::SymmetrySpec& s, EnvParams& p) {
  return std::make_unique<MjcfTask>(std::move(m), s, p);
}

}  // namespace masa::task
