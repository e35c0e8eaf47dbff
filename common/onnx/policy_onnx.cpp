#include "common/onnx/policy_onnx.hpp"

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "common/core/build_info.hpp"
#include "common/model/agent_maps.hpp"
#include "common/onnx/onnx_graph.hpp"

namespace masa::onnx_export {
namespace {

// Opset 13 (ONNX 1.8, 2020): read by Debian 12's checker, onnxruntime >= 1.6 and TensorRT 8.
constexpr int64_t kOpsetVersion = 13;
constexpr int64_t kIrVersion = 7;  // the IR version that came with opset 13

const std::string kBatch = "batch";

// The agents whose outputs reach the action (SASA's orbit copies other than 0 do not).
std::vector<int> agentsThatAct(const model::AgentMaps& maps) {
  std::vector<int> agents;
  for (int i = 0; i < maps.num_agents; ++i)
    if (maps.output[i].nonZeros() > 0) agents.push_back(i);
  return agents;
}

bool isIdentity(const sym::SparseMap& m) { return m.rows() == m.cols() && m.toDense().isIdentity(0.0); }

// [obs_dim, n * in]: column block a is In_(agents[a])^T, so that one MatMul gives every agent's input.
std::vector<float> stackedInputMaps(const model::AgentMaps& maps, const std::vector<int>& agents) {
  const int64_t n = static_cast<int64_t>(agents.size()), in = maps.agent_input_dim, cols = n * in;
  std::vector<float> m(static_cast<size_t>(maps.obs_dim * cols), 0.0f);
  for (int64_t a = 0; a < n; ++a) {
    const Eigen::MatrixXd t = maps.input[agents[a]].toDense();  // in x obs_dim
    for (int64_t r = 0; r < in; ++r)
      for (int64_t c = 0; c < maps.obs_dim; ++c) m[c * cols + a * in + r] = static_cast<float>(t(r, c));
  }
  return m;
}

// [n * in]: the agents' constant inputs (MA's one-hot ids) in the same stacked layout.
std::vector<float> stackedInputConstants(const model::AgentMaps& maps, const std::vector<int>& agents) {
  std::vector<float> c;
  for (int i : agents)
    for (int r = 0; r < maps.agent_input_dim; ++r) c.push_back(static_cast<float>(maps.input_constant(r, i)));
  return c;
}

// [n * out, act_dim]: row block a is Out_(agents[a])^T, so that one MatMul sums the agents' actions.
std::vector<float> stackedOutputMaps(const model::AgentMaps& maps, const std::vector<int>& agents) {
  const int64_t out = maps.agent_output_dim, act = maps.act_dim;
  std::vector<float> m(static_cast<size_t>(static_cast<int64_t>(agents.size()) * out * act), 0.0f);
  for (size_t a = 0; a < agents.size(); ++a) {
    const Eigen::MatrixXd t = maps.output[agents[a]].toDense();  // act_dim x out
    for (int64_t k = 0; k < out; ++k)
      for (int64_t j = 0; j < act; ++j) m[(static_cast<int64_t>(a) * out + k) * act + j] = static_cast<float>(t(j, k));
  }
  return m;
}

std::vector<float> toVector(const Eigen::Ref<const Vec<float>>& v) { return {v.data(), v.data() + v.size()}; }

const char* activationOp(nn::Activation a) {
  switch (a) {
    case nn::Activation::kElu: return "Elu";
    case nn::Activation::kTanh: return "Tanh";
    case nn::Activation::kRelu: return "Relu";
    case nn::Activation::kIdentity: return nullptr;
  }
  return nullptr;
}

// Phi, one Gemm (plus its activation) per layer, from the parameter segments "policy.layer<k>.*"
// that nn::Mlp reserved. A weight is out x in column-major, which is W^T row-major: Gemm's B as is.
std::string addSharedPolicyNet(OnnxGraph& g, const model::ActorCritic<float>& model, std::string x,
                               int input_width, const std::string& output) {
  const auto& params = model.params();
  const int layers = static_cast<int>(model.config().policy_hidden.size()) + 1;
  int width = input_width;
  for (int k = 0; k < layers; ++k) {
    const std::string name = "policy.layer" + std::to_string(k);
    const nn::ParameterSegment& w = params.segment(name + ".weight");
    const nn::ParameterSegment& b = params.segment(name + ".bias");
    MASA_CHECK(w.cols == width && b.rows == w.rows, name << " is " << w.rows << "x" << w.cols << " after width " << width);
    const float* values = params.values().data();
    const std::string& weight = g.floatInitializer(name + ".weight_t", {w.cols, w.rows},
                                                   {values + w.offset, values + w.offset + w.size()});
    const std::string& bias = g.floatInitializer(name + ".bias", {b.rows}, {values + b.offset, values + b.offset + b.size()});
    // The last layer is linear (SharedAgentPolicy's output activation is the identity).
    const char* act = k + 1 < layers ? activationOp(model.config().activation) : nullptr;
    const std::string linear = k + 1 == layers ? output : act ? name + ".linear" : name;
    g.node("Gemm", {x, weight, bias}, linear);
    x = linear;
    if (act) {
      onnx::NodeProto& n = g.node(act, {linear}, name);
      if (model.config().activation == nn::Activation::kElu) setAttribute(n, "alpha", 1.0f);  // masa's ELU: exp(z) - 1
      x = name;
    }
    width = w.rows;
  }
  return x;
}

std::string symmetryName(const sym::Group& group) {
  const char axis = static_cast<char>('x' + static_cast<int>(group.axis));
  if (group.type == sym::GroupType::kReflection) return std::string("C2 reflection, mirror normal ") + axis;
  std::string name = "C";  // built by appending: GCC 12 warns (-Wrestrict) on "C" + std::to_string(...)
  name += std::to_string(group.order) + " rotation about " + axis;
  return name;
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ",") + n;
  return s;
}

void addMetadata(onnx::ModelProto& m, const policy::LoadedPolicy& p) {
  const auto add = [&](const std::string& key, const std::string& value) {
    auto* e = m.add_metadata_props();
    e->set_key(key);
    e->set_value(value);
  };
  add("task", p.config.task);
  add("method", model::methodName(p.config.method));
  add("symmetry", symmetryName(p.spec.group()));
  add("observation_names", joined(p.spec.obsNames()));
  add("action_names", joined(p.spec.actNames()));
  add("activation", nn::activationName(p.config.model.activation));
  add("action_squash", model::actionSquashName(p.model->config().squash));
  add("masa_commit", masa::buildCommit());
  add("source_policy", p.source);
}

}  // namespace

onnx::ModelProto buildPolicyOnnx(const policy::LoadedPolicy& policy) {
  MASA_CHECK(policy.model != nullptr, "buildPolicyOnnx: the policy has no model");
  const model::ActorCritic<float>& model = *policy.model;
  const model::AgentMaps maps = model::buildAgentMaps(model.config().method, model.spec());
  const std::vector<int> agents = agentsThatAct(maps);
  const int64_t n = static_cast<int64_t>(agents.size()), in = maps.agent_input_dim, out = maps.agent_output_dim;

  onnx::ModelProto m;
  m.set_ir_version(kIrVersion);
  m.set_producer_name("masa");
  m.set_producer_version(masa::buildCommit());
  m.set_doc_string("Policy mean of a masa policy file, observation normalizer included: feed raw observations.");
  auto* opset = m.add_opset_import();
  opset->set_domain("");
  opset->set_version(kOpsetVersion);
  addMetadata(m, policy);
  onnx::GraphProto* graph = m.mutable_graph();
  graph->set_name(policy.config.task + "_" + model::methodName(policy.config.method) + "_policy");
  OnnxGraph g(graph);
  g.input("observation", {kBatch, int64_t{maps.obs_dim}});
  g.output("action_mean", {kBatch, int64_t{maps.act_dim}});
  g.output("log_std", {int64_t{maps.act_dim}});

  std::string x = "observation";
  if (model.config().normalize_obs) {
    const auto& norm = model.obsNormalizer();
    g.node("Sub", {x, g.floatInitializer("obs_mean", {maps.obs_dim}, toVector(norm.shift()))}, "obs_centered");
    g.node("Mul", {"obs_centered", g.floatInitializer("obs_inv_std", {maps.obs_dim}, toVector(norm.invScale()))},
           "obs_normalized");
    x = "obs_normalized";
  }
  // Agent inputs [batch * n, in], agent a of sample b in row b * n + a.
  const bool has_constants = maps.input_constant.any();
  if (n > 1 || !isIdentity(maps.input[agents[0]]) || has_constants) {
    g.node("MatMul", {x, g.floatInitializer("agent_input_maps", {maps.obs_dim, n * in}, stackedInputMaps(maps, agents))},
           "agent_inputs_stacked");
    x = "agent_inputs_stacked";
    if (has_constants) {
      g.node("Add", {x, g.floatInitializer("agent_input_constants", {n * in}, stackedInputConstants(maps, agents))},
             "agent_inputs_with_ids");
      x = "agent_inputs_with_ids";
    }
    if (n > 1) {
      g.node("Reshape", {x, g.int64Initializer("agent_rows_shape", {2}, {-1, in})}, "agent_inputs");
      x = "agent_inputs";
    }
  }
  // Phi on every agent at once, then the agents' actions summed through their output maps.
  // A squashed (SAC) policy's action is tanh of the network's mean: one Tanh node last.
  const bool squashed = model.config().squash == model::ActionSquash::kTanh;
  const std::string mean_name = squashed ? "action_before_tanh" : "action_mean";
  const bool needs_output_map = n > 1 || !isIdentity(maps.output[agents[0]]);
  x = addSharedPolicyNet(g, model, x, static_cast<int>(in), needs_output_map ? "agent_outputs" : mean_name);
  if (needs_output_map) {
    if (n > 1) {
      g.node("Reshape", {x, g.int64Initializer("agent_columns_shape", {2}, {-1, n * out})}, "agent_outputs_stacked");
      x = "agent_outputs_stacked";
    }
    g.node("MatMul", {x, g.floatInitializer("agent_output_maps", {n * out, maps.act_dim}, stackedOutputMaps(maps, agents))},
           mean_name);
  }
  if (squashed) g.node("Tanh", {mean_name}, "action_mean");
  Vec<float> log_std(maps.act_dim);
  model.logStd(log_std);
  g.floatConstant("log_std", {maps.act_dim}, toVector(log_std));
  return m;
}

void writePolicyOnnx(const policy::LoadedPolicy& policy, const std::string& path) {
  const onnx::ModelProto m = buildPolicyOnnx(policy);
  const std::string tmp = path + ".tmp";
  {
    std::ofstream os(tmp, std::ios::binary | std::ios::trunc);
    if (!os) throw std::runtime_error(tmp + ": cannot write");
    if (!m.SerializeToOstream(&os)) throw std::runtime_error(tmp + ": serializing the ONNX model failed");
    os.flush();
    if (!os) throw std::runtime_error(tmp + ": write failed");
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace masa::onnx_export
