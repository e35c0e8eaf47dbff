// Pushes during an episode (issue #52, env.randomization.push_velocity / push_interval_s): a
// horizontal velocity change of the robot base, as a kick or a bump would give a real robot.
//
// Whether a control step pushes, and how, is a function of the episode's seed and the step alone
// (no state of its own): a copied task or a resumed actor pushes alike. Each step pushes with
// probability step_s / interval_s (on average one push per interval); the change has a direction
// uniform on the circle and a size uniform in [0, max_velocity].
//
// Symmetric in distribution: that distribution of horizontal velocity changes is the same under
// every rotation and reflection about the vertical, so the image of an episode under the robot's
// symmetry (a mirror, a quarter turn) is pushed as likely as the episode itself. It is not
// symmetric sample by sample (the same seed pushes the same world direction), so the verifier is
// run without pushes, as without observation noise.
#pragma once

#include <cstdint>

namespace masa::task {

struct Push {
  double dvx = 0.0, dvy = 0.0;  // world frame, m/s
};

// The push of control step `step` (0-based) of the episode with `episode_seed`; false: none.
bool pushAtStep(double max_velocity, double interval_s, double step_s, uint64_t episode_seed, int step, Push* push);

}  // namespace masa::task
