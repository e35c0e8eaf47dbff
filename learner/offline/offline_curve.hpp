// The gnuplot script of an offline run's learning_curve.png, drawn from its metrics.csv (columns of
// offline_run.hpp): evaluation return and success against gradient steps, the algorithm's losses,
// its diagnostic figures, and throughput. Rendered by learner::LearningCurve like a PPO run's.
#pragma once

#include <string>
#include <vector>

namespace masa::offline {

// losses: metrics.csv columns drawn on the loss panel; figures: other columns of the algorithm
// (means of Q, V, advantage, weights...), drawn on their own panel. evaluates: whether the run
// evaluates at all (otherwise the evaluation panels say so instead of plotting empty columns).
std::string offlineCurveScript(const std::string& title, const std::vector<std::string>& losses,
                               const std::vector<std::string>& figures, bool evaluates);

}  // namespace masa::offline
