// The off-policy learner's fast gradient step (issue #50) against a straightforward reference, on
// TriFinger Lift's spec (MASA, 3 agents) at the recipe's sizes (networks 256-256, batch 256):
//   - the fast paths that only skip work give the bits of the full ones: the twin Q's action
//     gradient without parameter gradients (SAC's actor) and Q_1 alone (TD3's actor) against the
//     full backward, and they leave Q's parameter gradients untouched;
//   - the float step on this build's kernels (the fused AVX2 or AVX-512 engine where there is one)
//     against the same step in double on the generic engine (Eigen products, separate elementwise
//     passes): each parameter tensor's gradient within 2e-5 of the reference, relative to the
//     tensor's norm. Float carries 6e-8 relative per operation; sums of 256-768 terms over three
//     layers and the pooled heads leave about 1e-6 here, and the tolerance keeps a margin of 20
//     for other CPUs' summation orders. An elementwise bound would be meaningless where a
//     gradient entry is a cancellation near zero.
//   - the comparison fails for a float network whose 256 x 256 weight is transposed.
// TD3 runs without target smoothing noise, so that float and double draw no different noise
// (std::normal_distribution<float> and <double> differ); SAC's critic and actor use the same Q
// passes as TD3's, and its actor the twin action gradient tested first.
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>
#include <string>

#include "common/config/sac_config.hpp"
#include "common/model/sac_policy.hpp"
#include "learner/offline/twin_q.hpp"
#include "learner/sac/replay_buffer.hpp"
#include "learner/sac/sac_critic_maps.hpp"
#include "learner/sac/td3_trainer.hpp"

namespace masa::sac {
namespace {

constexpr double kFastStepTolerance = 2e-5;  // relative to each tensor's norm (see the header)
constexpr int kBatch = 256;

const sym::SymmetrySpec& trifinger() {
  static const sym::SymmetrySpec spec = sym::SymmetrySpec::load(
      (std::filesystem::path(MASA_SOURCE_DIR) / "configs/specs/trifinger_lift.yaml").string());
  return spec;
}

template <typename S>
offline::TwinQ<S> makeQ() {
  const SacConfig defaults;
  return offline::TwinQ<S>(trifinger(), twinQMaps(model::Method::kMasa, trifinger()), defaults.q_hidden,
                           nn::Activation::kElu);
}

// The largest over the tensors of ||got - want|| / ||want|| (tensors whose reference is zero
// compare absolutely), and the tensor where it is.
struct Mismatch {
  double relative = 0;
  std::string where;
};
Mismatch worstTensor(const nn::ParameterSet<float>& got, const Vec<float>& got_grads, const nn::ParameterSet<double>& want,
                     const Vec<double>& want_grads) {
  Mismatch m;
  for (const auto& s : want.segments()) {
    const Vec<double> w = want_grads.segment(s.offset, s.size());
    const Vec<double> g = got_grads.segment(s.offset, s.size()).cast<double>();
    const double scale = w.norm() > 0 ? w.norm() : 1.0;
    const double r = (g - w).norm() / scale;
    if (r > m.relative) m = {r, s.name};
  }
  EXPECT_EQ(got.size(), want.size());
  return m;
}

double relativeError(const Mat<float>& got, const Mat<double>& want) {
  return (got.cast<double>() - want).norm() / want.norm();
}

TEST(OffPolicyFastStep, ActionGradientsWithoutParameterGradientsGiveTheFullBackwardsBits) {
  offline::TwinQ<float> q = makeQ<float>();
  Rng rng(3);
  q.initialize(rng);
  const int obs = trifinger().obsDim(), act = trifinger().actDim();
  const Mat<float> o = Mat<float>::Random(obs, kBatch), a = Mat<float>::Random(act, kBatch);
  const Mat<float> dq = Mat<float>::Random(2, kBatch);

  q.params().grads().setConstant(0.25f);
  const Vec<float> grads_before = q.params().grads();
  q.forward(o, a);
  Mat<float> fast(act, kBatch);
  q.actionGradient(dq, fast);
  EXPECT_TRUE(q.params().grads() == grads_before) << "the action gradient wrote Q's parameter gradients";
  q.forward(o, a);
  Mat<float> full(act, kBatch);
  MatRef<float> full_ref(full);
  q.backward(dq, &full_ref);
  EXPECT_TRUE(fast == full) << "twin action gradient: max difference " << (fast - full).cwiseAbs().maxCoeff();

  // Q_1 alone: its values and its action gradient are those of the twin with dL/dQ_2 = 0.
  const Mat<float> twin_q = q.forward(o, a);
  q.params().grads() = grads_before;
  const Mat<float> q1 = q.q1Forward(o, a);
  EXPECT_TRUE(q1 == twin_q.row(0)) << "Q_1 alone differs from the twin's first row";
  Mat<float> fast1(act, kBatch);
  q.q1ActionGradient(dq.row(0), fast1);
  EXPECT_TRUE(q.params().grads() == grads_before) << "Q_1's action gradient wrote Q's parameter gradients";
  Mat<float> dq_first = dq;
  dq_first.row(1).setZero();
  q.forward(o, a);
  q.backward(dq_first, &full_ref);
  EXPECT_TRUE(fast1 == full) << "Q_1 action gradient: max difference " << (fast1 - full).cwiseAbs().maxCoeff();
}

TEST(OffPolicyFastStep, TwinActionGradientsMatchTheDoubleGenericEngine) {
  offline::TwinQ<float> qf = makeQ<float>();
  offline::TwinQ<double> qd = makeQ<double>();
  Rng rng(4);
  qf.initialize(rng);
  qd.params().values() = qf.params().values().cast<double>();
  const int obs = trifinger().obsDim(), act = trifinger().actDim();
  const Mat<float> o = Mat<float>::Random(obs, kBatch), a = Mat<float>::Random(act, kBatch);
  const Mat<float> dq = Mat<float>::Random(2, kBatch);
  const Mat<float> values = qf.forward(o, a);
  Mat<float> da(act, kBatch);
  qf.actionGradient(dq, da);
  const Mat<double> values_d = qd.forward(o.cast<double>(), a.cast<double>());
  Mat<double> da_d(act, kBatch);
  MatRef<double> da_d_ref(da_d);
  qd.backward(dq.cast<double>(), &da_d_ref);
  EXPECT_LT(relativeError(values, values_d), kFastStepTolerance);
  EXPECT_LT(relativeError(da, da_d), kFastStepTolerance);
  EXPECT_GT(da_d.norm(), 1e-3);
}

// One TD3 learner in float (this build's kernels) and one in double (the generic engine) from the
// same parameters and batch.
struct Td3Pair {
  SacConfig config;
  SacPolicy<float> policy_f{trifinger(), shape()};
  SacPolicy<double> policy_d{trifinger(), shape()};
  offline::TwinQ<float> q_f = makeQ<float>(), q_target_f = makeQ<float>();
  offline::TwinQ<double> q_d = makeQ<double>(), q_target_d = makeQ<double>();
  ReplayBatch<float> batch_f;
  ReplayBatch<double> batch_d;

  static SacPolicyShape shape() {
    SacPolicyShape s;
    s.method = model::Method::kMasa;
    return s;
  }

  Td3Pair() {
    config.algorithm = "td3";
    config.td3_policy_noise = 0.0;  // no draws whose values differ between float and double
    Rng rng(5);
    policy_f.initialize(rng, 1.0f);  // a last layer of full scale: actions away from zero
    q_f.initialize(rng);
    q_target_f.initialize(rng);
    policy_d.params().values() = policy_f.params().values().cast<double>();
    q_d.params().values() = q_f.params().values().cast<double>();
    q_target_d.params().values() = q_target_f.params().values().cast<double>();
    const int obs = trifinger().obsDim(), act = trifinger().actDim();
    batch_f.resize(obs, act, kBatch);
    batch_f.obs.setRandom();
    batch_f.next_obs.setRandom();
    batch_f.actions.setRandom();
    batch_f.rewards.setRandom();
    batch_f.discount.setConstant(0.97f);
    batch_d.resize(obs, act, kBatch);
    batch_d.obs = batch_f.obs.cast<double>();
    batch_d.next_obs = batch_f.next_obs.cast<double>();
    batch_d.actions = batch_f.actions.cast<double>();
    batch_d.rewards = batch_f.rewards.cast<double>();
    batch_d.discount = batch_f.discount.cast<double>();
  }
};

// The critic's and the actor's gradients of the float step against the double reference; with
// `transpose_q_weight`, the float Q_1's hidden 256 x 256 weight is transposed first (what a kernel
// reading W for W^T would compute).
struct Td3Errors {
  Mismatch critic, actor;
};
Td3Errors td3Errors(bool transpose_q_weight) {
  Td3Pair p;
  if (transpose_q_weight)
    for (const auto& s : p.q_f.params().segments())
      if (s.rows == 256 && s.cols == 256) {
        auto w = p.q_f.params().value(s.offset, s.rows, s.cols);
        w = Mat<float>(w.transpose());
        break;
      }
  Td3Trainer<float> fast(trifinger(), p.policy_f, p.q_f, p.q_target_f, p.config);
  Td3Trainer<double> reference(trifinger(), p.policy_d, p.q_d, p.q_target_d, p.config);
  Rng rf(9), rd(9);
  Td3Errors e;
  const double loss_f = fast.criticLoss(p.batch_f, rf), loss_d = reference.criticLoss(p.batch_d, rd);
  EXPECT_GT(p.q_d.params().grads().norm(), 1e-3);
  e.critic = worstTensor(p.q_f.params(), p.q_f.params().grads(), p.q_d.params(), p.q_d.params().grads());
  if (!transpose_q_weight) {
    EXPECT_NEAR(loss_f, loss_d, kFastStepTolerance * std::abs(loss_d));
  }
  const double actor_f = fast.actorLoss(p.batch_f), actor_d = reference.actorLoss(p.batch_d);
  EXPECT_GT(p.policy_d.params().grads().norm(), 1e-3);
  e.actor = worstTensor(p.policy_f.params(), p.policy_f.params().grads(), p.policy_d.params(),
                        p.policy_d.params().grads());
  if (!transpose_q_weight) {
    EXPECT_NEAR(actor_f, actor_d, kFastStepTolerance * (1 + std::abs(actor_d)));
  }
  return e;
}

TEST(OffPolicyFastStep, Td3GradientsMatchTheDoubleGenericEngineTensorByTensor) {
  const Td3Errors e = td3Errors(false);
  EXPECT_LT(e.critic.relative, kFastStepTolerance) << "critic, worst tensor " << e.critic.where;
  EXPECT_LT(e.actor.relative, kFastStepTolerance) << "actor, worst tensor " << e.actor.where;
  std::cout << "float against double, worst tensor: critic " << e.critic.relative << " (" << e.critic.where
            << "), actor " << e.actor.relative << " (" << e.actor.where << ")\n";
}

TEST(OffPolicyFastStep, TheComparisonCatchesATransposedWeight) {
  const Td3Errors e = td3Errors(true);
  EXPECT_GT(e.critic.relative, 100 * kFastStepTolerance) << "a transposed Q weight went unnoticed by the critic";
  EXPECT_GT(e.actor.relative, 100 * kFastStepTolerance) << "a transposed Q weight went unnoticed by the actor";
}

}  // namespace
}  // namespace masa::sac
