// The actor's check of a parameter message (actors/params_check.hpp): a well-formed message of
// the run passes; each way of being wrong is refused with its reason, before anything is taken.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include "actors/params_check.hpp"

namespace masa::actor {
namespace {

ParamsExpectation expectation() {
  return {.run_id = 77, .task = "a1_beam", .method = "masa", .policy_param_count = 5, .model_param_count = 9,
          .obs_dim = 3, .max_version_step = 100};
}

masa::lcmt_policy_params goodMessage() {
  masa::lcmt_policy_params m{};
  m.run_id = 77;
  m.version = 4;
  m.task = "a1_beam";
  m.method = "masa";
  m.num_params = 5;
  m.params = {0.1f, -0.2f, 0.3f, 0.0f, 1.0f};
  m.obs_dim = 3;
  m.obs_mean = {0.0f, 1.0f, -1.0f};
  m.obs_std = {1.0f, 0.5f, 2.0f};
  return m;
}

TEST(ParamsCheck, AWellFormedMessageOfTheRunPassesWithThePolicyOrTheWholeModel) {
  const ParamsCheck check(expectation());
  masa::lcmt_policy_params m = goodMessage();
  EXPECT_TRUE(check.ofThisRun(m));
  EXPECT_EQ(check.refusal(m, 3), std::nullopt);
  m.num_params = 9;
  m.params.assign(9, 0.5f);
  EXPECT_EQ(check.refusal(m, 3), std::nullopt);
  m.obs_dim = 0;  // a learner that does not normalize
  m.obs_mean.clear();
  m.obs_std.clear();
  EXPECT_EQ(check.refusal(m, 3), std::nullopt);
  m.run_id = 78;
  EXPECT_FALSE(check.ofThisRun(m));
}

TEST(ParamsCheck, EachWayOfBeingWrongIsRefusedWithItsReason) {
  const ParamsCheck check(expectation());
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::pair<std::function<void(masa::lcmt_policy_params&)>, std::string> cases[] = {
      {[](auto& m) { m.version = 3 + 101; }, "more than 100 versions ahead of 3"},
      {[](auto& m) { m.task = "ant_acrobatic"; }, "task 'ant_acrobatic', this actor runs 'a1_beam'"},
      {[](auto& m) { m.method = "sa"; }, "method 'sa', this actor builds 'masa'"},
      {[](auto& m) { m.num_params = 6; m.params.assign(6, 0.0f); }, "num_params 6, expected 5 (policy) or 9 (whole model)"},
      {[](auto& m) { m.params.pop_back(); }, "params array length differs from num_params"},
      {[](auto& m) { m.obs_dim = 4; m.obs_mean.push_back(0); m.obs_std.push_back(1); }, "obs_dim 4, expected 3"},
      {[](auto& m) { m.obs_std.pop_back(); }, "normalizer arrays differ from obs_dim"},
      {[nan](auto& m) { m.params[2] = nan; }, "non-finite parameter"},
      {[](auto& m) { m.params[0] = std::numeric_limits<float>::infinity(); }, "non-finite parameter"},
      {[](auto& m) { m.obs_std[1] = 0.0f; }, "bad normalizer entry 1"},
      {[nan](auto& m) { m.obs_mean[2] = nan; }, "bad normalizer entry 2"},
  };
  for (const auto& [mutate, reason] : cases) {
    masa::lcmt_policy_params m = goodMessage();
    mutate(m);
    const auto why = check.refusal(m, 3);
    ASSERT_TRUE(why.has_value()) << reason;
    EXPECT_EQ(*why, reason);
  }
}

// The step limit applies to versions ahead of the actor's only: a late copy of an older version is
// the actor's decision (it usually ignores it), not a malformed message.
TEST(ParamsCheck, TheVersionStepLimitsOnlyMessagesAhead) {
  const ParamsCheck check(expectation());
  masa::lcmt_policy_params m = goodMessage();
  m.version = 2;
  EXPECT_EQ(check.refusal(m, 500), std::nullopt);
  m.version = 100;  // from nothing yet (-1): 100 ahead of 0 is the limit, allowed
  EXPECT_EQ(check.refusal(m, -1), std::nullopt);
  m.version = 101;
  EXPECT_TRUE(check.refusal(m, -1).has_value());
}

}  // namespace
}  // namespace masa::actor
