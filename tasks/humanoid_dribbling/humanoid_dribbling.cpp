#include "tasks/humanoid_dribbling/humanoid_dribbling.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "common/core/config_error.hpp"
#include "tasks/tasks.hpp"

namespace masa::task {

namespace {
constexpr double kDeg = M_PI / 180.0;
constexpr int kBallObs = 6;      // the ball's position and velocity
constexpr int kNextTurnObs = 3;  // env.observe_next_turn: the turn's distance ahead, the next heading

// How far the point p (world x, y) is along segment frame f, from its start.
double alongSegment(const PlanarFrame& f, const double* p) {
  return std::cos(f.heading) * (p[0] - f.x) + std::sin(f.heading) * (p[1] - f.y);
}

// Read before the humanoid body checks the spec's layout, which depends on it: a spec without the
// next turn's entries (or with them, and the option off) is named here with the way out.
int extraCentralObs(EnvParams& params, const sym::SymmetrySpec& spec) {
  const bool next_turn = params.flag("observe_next_turn", false);
  const int extra = kBallObs + (next_turn ? kNextTurnObs : 0);
  const int has = spec.obsCentralDim() - HumanoidTask::kTorsoObs - 3 * spec.actCentralDim();
  if (has != extra && (has == kBallObs || has == kBallObs + kNextTurnObs))
    throw ConfigError(params.origin("observe_next_turn"), "env.observe_next_turn",
                      std::string(next_turn ? "true" : "false") + " needs " + std::to_string(extra) +
                          " central entries after the abdomen's (the ball's" +
                          (next_turn ? " and the next turn's" : "") + "), but " + spec.source() + " has " +
                          std::to_string(has) + "; set spec: " +
                          (next_turn ? "configs/specs/humanoid_dribbling_next_turn.yaml"
                                     : "\"\" (the task's own, configs/specs/humanoid_dribbling.yaml)") +
                          " (or use the recipe humanoid_dribbling_next_turn)");
  return extra;
}
}  // namespace

HumanoidDribbling::HumanoidDribbling(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec,
                                     EnvParams& params)
    : HumanoidTask("humanoid_dribbling", std::move(model), spec, params,
                   {{"velocity", 2.0},
                    {"alive", 0.2},
                    {"dist", 0.2},
                    {"heading", 1.0},
                    {"action", -0.01},
                    {"energy", -0.05},
                    {"lateral", -0.5}},
                   /*start_hip_x_default=*/0.0, extraCentralObs(params, spec)) {
  const mjModel* m = model_->get();
  const int ball = model_->id(mjOBJ_JOINT, "ball");
  ball_qpos_ = m->jnt_qposadr[ball];
  ball_dof_ = m->jnt_dofadr[ball];
  ball_radius_ = m->geom_size[3 * model_->id(mjOBJ_GEOM, "ball")];
  ball_distance_ = params.positive("ball_distance", 0.6);
  fall_height_ = params.positive("fall_height", 0.4);
  max_ball_distance_ = params.positive("max_ball_distance", 5.0);
  velocity_cap_ = params.number("velocity_cap", 0.0);
  if (velocity_cap_ < 0.0) throw ConfigError(params.origin("velocity_cap"), "env.velocity_cap",
                                             "must be 0 (uncapped) or a speed in m/s, got " + std::to_string(velocity_cap_));
  const std::string lateral = params.text("lateral_penalty", "abs");
  if (lateral != "abs" && lateral != "squared")
    throw ConfigError(params.origin("lateral_penalty"), "env.lateral_penalty", "must be abs or squared, got '" + lateral + "'");
  lateral_squared_ = lateral == "squared";
  const std::string anchor = params.text("route_anchor", "torso");
  if (anchor != "torso" && anchor != "ball")
    throw ConfigError(params.origin("route_anchor"), "env.route_anchor", "must be torso or ball, got '" + anchor + "'");
  anchor_ball_ = anchor == "ball";
  observe_next_turn_ = params.flag("observe_next_turn", false);
  segment_min_ = params.positive("segment_length_min", 4.0);
  segment_max_ = params.positive("segment_length_max", 8.0);
  turn_min_ = params.number("turn_min_deg", 30.0) * kDeg;
  turn_max_ = params.number("turn_max_deg", 90.0) * kDeg;
  const int segments = params.integer("route_segments", 32, 1);
  MASA_CHECK(segment_min_ <= segment_max_, "env.segment_length_min must not exceed env.segment_length_max");
  MASA_CHECK(0.0 <= turn_min_ && turn_min_ <= turn_max_ && turn_max_ <= M_PI,
             "env.turn_min_deg and env.turn_max_deg must satisfy 0 <= min <= max <= 180");
  route_.resize(segments);
  length_.resize(segments);
}

void HumanoidDribbling::resetTask(Rng& rng) {
  randomizePose(rng);
  start_z_ = standOnGround();
  double* b = data_->qpos + ball_qpos_;
  b[0] = ball_distance_;
  b[1] = 0.0;
  b[2] = ball_radius_;
  for (int k = 0; k < 6; ++k) data_->qvel[ball_dof_ + k] = 0.0;

  // The first segment starts under the torso along +x; each later one turns left or right.
  std::uniform_real_distribution<double> len(segment_min_, segment_max_), turn(turn_min_, turn_max_);
  std::bernoulli_distribution left(0.5);
  route_[0] = PlanarFrame{};
  for (size_t k = 0; k < route_.size(); ++k) {
    length_[k] = len(rng);
    if (k + 1 == route_.size()) break;
    const PlanarFrame& s = route_[k];
    const double dturn = left(rng) ? turn(rng) : -turn(rng);
    route_[k + 1] = PlanarFrame{s.x + length_[k] * std::cos(s.heading), s.y + length_[k] * std::sin(s.heading),
                                s.heading + dturn};
  }
  length_.back() = std::numeric_limits<double>::infinity();
  current_ = 0;
}

const double* HumanoidDribbling::ballPos() const { return data_->qpos + ball_qpos_; }
const double* HumanoidDribbling::ballLinVel() const { return data_->qvel + ball_dof_; }

double HumanoidDribbling::torsoBallDistance() const {
  const double* t = torsoPos();
  const double* b = ballPos();
  return std::hypot(b[0] - t[0], b[1] - t[1]);
}

void HumanoidDribbling::writeObservation(float* out) const {
  const PlanarFrame& f = route_[current_];
  writeHumanoidCentral(f, out);
  float* ball = out + kTorsoObs + 3 * spec().actCentralDim();
  const double* t = torsoPos();
  const double* b = ballPos();
  const double* v = ballLinVel();
  const double rel[2] = {b[0] - t[0], b[1] - t[1]};
  double loc[2];
  f.rotateIn(rel, loc);  // ball relative to the torso, in the segment frame
  ball[0] = static_cast<float>(loc[0]);
  ball[1] = static_cast<float>(loc[1]);
  ball[2] = static_cast<float>(b[2]);
  f.rotateIn(v, loc);
  ball[3] = static_cast<float>(loc[0]);
  ball[4] = static_cast<float>(loc[1]);
  ball[5] = static_cast<float>(v[2]);
  if (observe_next_turn_) {
    // How far ahead of the torso the segment ends (clipped: the last never ends) and where the next
    // one heads, relative to this one (straight on after the last).
    const bool last = current_ + 1 == numSegments();
    const double ahead = length_[current_] - alongSegment(f, t);
    const double turn = last ? 0.0 : route_[current_ + 1].heading - f.heading;
    float* next = ball + kBallObs;
    next[0] = static_cast<float>(std::clamp(ahead, -segment_max_, segment_max_));
    next[1] = static_cast<float>(std::cos(turn));
    next[2] = static_cast<float>(std::sin(turn));
  }
  writeLimbs(out + spec().obsCentralDim());
}

void HumanoidDribbling::computeRewardTerms(double* t) const {
  const PlanarFrame& f = route_[current_];
  double v[2], r[9];
  f.rotateIn(ballLinVel(), v);
  torsoRotation(r);
  t[0] = velocity_cap_ > 0.0 ? std::min(v[0], velocity_cap_) : v[0];   // velocity: ball along the segment
  t[1] = 1.0;                                                           // alive
  t[2] = std::exp(-torsoBallDistance());                                // dist
  t[3] = std::cos(f.heading) * r[0] + std::sin(f.heading) * r[3];       // heading: torso x axis . segment
  t[4] = actionSquaredNorm();                                           // action
  t[5] = jointPower();                                                 // energy
  t[6] = lateral_squared_ ? v[1] * v[1] : std::abs(v[1]);              // lateral: ball lateral velocity
}

bool HumanoidDribbling::isTerminated() const {
  return torsoPos()[2] < start_z_ - fall_height_ || torsoBallDistance() > max_ball_distance_ || tiltedPastLimit();
}

void HumanoidDribbling::afterStep() {
  // Re-anchor at each turn the torso (or the ball) has passed (along-track distance beyond the
  // segment's end).
  const double* p = anchor_ball_ ? ballPos() : torsoPos();
  while (current_ + 1 < numSegments()) {
    const PlanarFrame& f = route_[current_];
    if (alongSegment(f, p) < length_[current_]) break;
    ++current_;
  }
}

void HumanoidDribbling::progress(double* out) const {
  double passed = 0.0;
  for (int k = 0; k < current_; ++k) passed += length_[k];
  const PlanarFrame& f = route_[current_];
  const double* b = ballPos();
  const double along = alongSegment(f, b);
  const double t = episode().length * controlTimestep();
  out[0] = passed + along;
  out[1] = current_;
  out[2] = t > 0 ? out[0] / t : 0.0;
}

void HumanoidDribbling::transformExtras(int i) {
  if (i % 2 == 0) return;
  // The mirror y -> -y maps the route onto its mirror image: turns flip, lengths and progress keep.
  for (PlanarFrame& f : route_) {
    f.y = -f.y;
    f.heading = -f.heading;
  }
}

void HumanoidDribbling::saveExtras(std::vector<double>& out) const {
  out.push_back(static_cast<double>(route_.size()));
  for (const PlanarFrame& f : route_) out.insert(out.end(), {f.x, f.y, f.heading});
  out.insert(out.end(), length_.begin(), length_.end());
  out.insert(out.end(), {static_cast<double>(current_), start_z_});
}

void HumanoidDribbling::loadExtras(std::span<const double> in) {
  // The route's segments, their frames and lengths, the current one and the start height.
  const double n = in.empty() ? -1.0 : in[0];
  if (!(n >= 0.0 && n == std::floor(n) && in.size() == 1 + 4 * static_cast<std::size_t>(n) + 2))
    throw std::runtime_error("humanoid_dribbling state: " + std::to_string(in.size()) +
                             " values of route, which cannot be a route of " + std::to_string(n) + " segments");
  const std::size_t segments = static_cast<std::size_t>(n);
  route_.resize(segments);
  length_.resize(segments);
  for (std::size_t k = 0; k < segments; ++k) route_[k] = {in[1 + 3 * k], in[2 + 3 * k], in[3 + 3 * k]};
  for (std::size_t k = 0; k < segments; ++k) length_[k] = in[1 + 3 * segments + k];
  current_ = static_cast<int>(in[1 + 4 * segments]);
  start_z_ = in[2 + 4 * segments];
}

// Listed in tasks/tasks.cpp.
std::unique_ptr<Task> makeHumanoidDribbling(std::shared_ptr<const MujocoModel> model, const sym::SymmetrySpec& spec,
                                            EnvParams& params) {
  return std::make_unique<HumanoidDribbling>(std::move(model), spec, params);
}

}  // namespace masa::task
