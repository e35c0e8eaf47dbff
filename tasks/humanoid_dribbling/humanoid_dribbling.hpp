// Humanoid Dribbling (paper appendix "Tasks Details"): dribble a ball along a route of straight
// segments with random turns; observations are expressed in the current segment's frame, which is
// re-anchored when the torso (env.route_anchor: ball, the ball) passes the segment's end. See README.md.
#pragma once

#include <vector>

#include "tasks/humanoid_tightrope/humanoid_body.hpp"

namespace masa::task {

class HumanoidDribbling final : public HumanoidTask {
 public:
  HumanoidDribbling(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec, EnvParams& params);

  // The route (world frame): segment k starts at segmentFrame(k) (x, y) with heading (rad) and
  // runs segmentLength(k) metres; the last segment never ends.
  int numSegments() const { return static_cast<int>(route_.size()); }
  int currentSegment() const { return current_; }
  const PlanarFrame& segmentFrame(int k) const { return route_[k]; }
  double segmentLength(int k) const { return length_[k]; }

  // How far along the route the ball got (m: whole segments passed plus the ball's along-track
  // distance in the current one), the segments passed, and the ball's mean speed along the route.
  std::vector<std::string> progressNames() const override { return {"route_m", "segments", "ball_speed_mps"}; }
  void progress(double* out) const override;

 protected:
  void resetTask(Rng& rng) override;
  void writeObservation(float* out) const override;
  void computeRewardTerms(double* t) const override;
  bool isTerminated() const override;
  void afterStep() override;
  void transformExtras(int i) override;
  void saveExtras(std::vector<double>& out) const override;
  void loadExtras(std::span<const double> in) override;

 private:
  const double* ballPos() const;
  const double* ballLinVel() const;
  double torsoBallDistance() const;  // 2-D, m

  int ball_qpos_, ball_dof_;
  double ball_radius_;
  double ball_distance_, fall_height_, max_ball_distance_;
  // Issue #31 (the kick): the ball's speed along the segment rewarded up to velocity_cap m/s (0:
  // uncapped, the paper), and its lateral speed penalized squared instead of absolute.
  double velocity_cap_ = 0.0;
  bool lateral_squared_ = false;
  // Issue #31 (the turns): which body's passing a segment's end moves the frame, and the reward's
  // "along the route", on to the next segment. The torso (the default) lets the ball, ahead of it,
  // roll past the turn while its speed along the old heading still pays; the ball turns them with it.
  bool anchor_ball_ = false;
  // Issue #31 (the turns): three more central observations, the distance from the torso to the
  // segment's end along it and the cosine and sine of the next turn, so that the policy can steer the
  // ball before the turn rather than chase it after (needs configs/specs/humanoid_dribbling_next_turn.yaml).
  bool observe_next_turn_ = false;
  double segment_min_, segment_max_, turn_min_, turn_max_;
  std::vector<PlanarFrame> route_;
  std::vector<double> length_;
  int current_ = 0;
  double start_z_ = 0.0;
};

}  // namespace masa::task
