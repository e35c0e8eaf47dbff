// What a parameter message must be before an actor takes anything from it: the actor's side of the
// learner's chunk validation (learner/intake/rollout_assembler.cpp). Stateless: which version to
// take (the learner's repeats, late copies, taking a version back) is the actor's decision, made
// after the message has passed.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "masa/lcmt_policy_params.hpp"

namespace masa::actor {

// What this actor expects of the parameters it runs.
struct ParamsExpectation {
  int64_t run_id = 0;
  std::string task;
  std::string method;                // model::methodName
  int policy_param_count = 0;        // the policy and log-std prefix of the flat parameters
  int model_param_count = 0;         // the whole model, critic included
  int obs_dim = 0;
  int64_t max_version_step = 1'000'000;  // how far past the actor's version a message may jump
};

class ParamsCheck {
 public:
  explicit ParamsCheck(ParamsExpectation expected) : expected_(std::move(expected)) {}

  // Why the message must not be used, or nothing when it may be. `newest` is the newest version
  // the actor holds or has pending (-1: none yet); a message at or below it is not checked for
  // its step. The run id is not checked here: another run's message is no error (see ofThisRun).
  std::optional<std::string> refusal(const masa::lcmt_policy_params& m, int64_t newest) const;
  bool ofThisRun(const masa::lcmt_policy_params& m) const { return m.run_id == expected_.run_id; }

  const ParamsExpectation& expected() const { return expected_; }

 private:
  ParamsExpectation expected_;
};

}  // namespace masa::actor
