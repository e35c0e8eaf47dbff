#include "common/sim/episode_pushes.hpp"

#include <cmath>
#include <numbers>
#include <random>

#include "common/core/types.hpp"

namespace masa::task {

bool pushAtStep(double max_velocity, double interval_s, double step_s, uint64_t episode_seed, int step, Push* push) {
  if (!(max_velocity > 0.0)) return false;
  // A generator of its own per step, apart from the observation noise's (another odd constant).
  Rng rng(episode_seed ^ (0xD1B54A32D192ED03ULL * static_cast<uint64_t>(step + 1)));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  if (u(rng) >= step_s / interval_s) return false;
  const double angle = 2.0 * std::numbers::pi * u(rng);
  const double size = max_velocity * u(rng);
  push->dvx = size * std::cos(angle);
  push->dvy = size * std::sin(angle);
  return true;
}

}  // namespace masa::task
