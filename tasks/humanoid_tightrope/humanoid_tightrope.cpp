// Humanoid Tightrope (paper appendix "Tasks Details"): walk forward (+x) on a rope of 10 cm
// diameter. See README.md for the observation, the reward terms and where we differ.
#include <cmath>
#include <string>


#include "tasks/tasks.hpp"
#include "tasks/humanoid_tightrope/humanoid_body.hpp"

namespace masa::task {
namespace {

class HumanoidTightrope final : public HumanoidTask {
 public:
  HumanoidTightrope(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec, EnvParams& params)
      : HumanoidTask("humanoid_tightrope", std::move(model), spec, params,
                     {{"velocity", 1.0},
                      {"alive", 2.0},
                      {"up", 0.1},
                      {"heading", 0.1},
                      {"action", -0.01},
                      {"energy", -0.05},
                      {"lateral", -1.0}},
                     /*start_hip_x_default=*/0.04, /*extra_central_obs=*/0) {
    const mjModel* m = model_->get();
    const int rope = model_->id(mjOBJ_GEOM, "rope");
    MASA_CHECK(m->geom_pos[3 * rope + 1] == 0.0, "the rope must lie on the mirror plane y = 0");
    rope_axis_z_ = m->geom_pos[3 * rope + 2];
    rope_radius_ = m->geom_size[3 * rope];
    fall_height_ = params.positive("fall_height", 0.75);
    up_threshold_ = params.number("up_threshold", 0.93);
  }

  // Metres walked along the rope (+x) from the start, and the mean speed over the episode.
  std::vector<std::string> progressNames() const override { return {"distance_m", "speed_mps"}; }
  void progress(double* out) const override {
    const double d = torsoPos()[0] - start_x_;
    const double t = episode().length * controlTimestep();
    out[0] = d;
    out[1] = t > 0 ? d / t : 0.0;
  }

 protected:
  void resetTask(Rng& rng) override {
    randomizePose(rng);
    start_z_ = standOnRope(rope_axis_z_, rope_radius_);
    start_x_ = torsoPos()[0];
  }

  void writeObservation(float* out) const override {
    writeHumanoidCentral(PlanarFrame{}, out);
    writeLimbs(out + spec().obsCentralDim());
  }

  void computeRewardTerms(double* t) const override {
    const double* v = torsoLinVel();
    double r[9];
    torsoRotation(r);
    t[0] = v[0];                              // velocity: forward torso velocity (m/s)
    t[1] = 1.0;                               // alive
    t[2] = r[8] > up_threshold_ ? 1.0 : 0.0;  // up: torso z axis' world z
    t[3] = r[0];                              // heading: torso x axis' world x
    t[4] = actionSquaredNorm();               // action
    t[5] = jointPower();                     // energy
    t[6] = std::abs(v[1]);                    // lateral: |v_y|, mirror-invariant (the paper's v_y is not)
  }

  bool isTerminated() const override { return torsoPos()[2] < start_z_ - fall_height_ || tiltedPastLimit(); }

  void saveExtras(std::vector<double>& out) const override { out.insert(out.end(), {start_z_, start_x_}); }
  void loadExtras(std::span<const double> in) override {
    if (in.size() != 2) throw std::runtime_error("humanoid_tightrope state: 2 extras expected, got " + std::to_string(in.size()));
    start_z_ = in[0];
    start_x_ = in[1];
  }
  // start_z_ is a height: invariant under the mirror, so transformExtras keeps the default.

 private:
  double rope_axis_z_ = 0.0, rope_radius_ = 0.0, fall_height_ = 0.0, up_threshold_ = 0.0;
  double start_z_ = 0.0, start_x_ = 0.0;  // x: along the rope, unchanged by the mirror
};

}  // namespace

// Listed in tasks/tasks.cpp.
std::unique_ptr<Task> makeHumanoidTightrope(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec,
                                            EnvParams& params) {
  return std::make_unique<HumanoidTightrope>(std::move(model), spec, params);
}

}  // namespace masa::task
