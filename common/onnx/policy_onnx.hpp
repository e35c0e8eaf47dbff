// A trained policy's mean as an ONNX model, so that a robot stack runs it without masa.
//
//   observation [batch, obs_dim] float32, raw, in the task's observation order
//   action_mean [batch, act_dim] float32, unclipped (masa's tasks clip each action to [-1, 1]);
//               for a squashed (SAC) policy file tanh of the mean, SAC's deterministic action
//   log_std     [act_dim]        float32, constant: the Gaussian's log-std, for sampling (a SAC
//               policy's noise depends on the observation: its file's log_std is no sampling noise)
//
// The graph is masa's inference written with standard operators (opset 13): the observation
// normalizer as trained ((o - mean) * 1/sqrt(var + eps), Sub and Mul), the method's agent input
// maps T_i stacked into one MatMul (plus MA's one-hot ids, Add), agents moved to the batch axis
// (Reshape) so that the shared network Phi runs once (Gemm and Elu/Tanh/Relu per layer), then
// agents back to columns and the output maps summed in one MatMul, then a Tanh for a squashed
// policy. SA is a plain MLP; SASA's orbit copies, which never reach the action, are left out.
// Metadata: task, method, symmetry, the observation and action names of the spec, the activation,
// action_squash ("none", or "tanh" when action_mean is tanh(mean)), the masa commit it was exported by.
#pragma once

#include <onnx/onnx_pb.h>

#include <string>

#include "common/policy/policy_file.hpp"

namespace masa::onnx_export {

onnx::ModelProto buildPolicyOnnx(const policy::LoadedPolicy& policy);

// Writes buildPolicyOnnx(policy) to `path` atomically (tmp + rename); throws std::runtime_error
// naming the file when it cannot.
void writePolicyOnnx(const policy::LoadedPolicy& policy, const std::string& path);

}  // namespace masa::onnx_export
