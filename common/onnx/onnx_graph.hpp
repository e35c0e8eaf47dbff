// A thin writer of ONNX graphs over the protobuf classes of Debian's libonnx-dev: float32 and
// int64 initializers from row-major data, nodes with their attributes, typed inputs and outputs.
// It knows nothing of masa's models; policy_onnx.hpp builds the policy with it.
#pragma once

#include <onnx/onnx_pb.h>

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

namespace masa::onnx_export {

// One dimension of a graph input or output: a fixed size, or a named free one ("batch").
using OnnxDim = std::variant<int64_t, std::string>;

class OnnxGraph {
 public:
  explicit OnnxGraph(onnx::GraphProto* graph) : graph_(graph) {}

  void input(const std::string& name, const std::vector<OnnxDim>& dims);
  void output(const std::string& name, const std::vector<OnnxDim>& dims);

  // Initializers hold row-major data of `dims`; each returns its name, for use as a node input.
  const std::string& floatInitializer(const std::string& name, const std::vector<int64_t>& dims,
                                      const std::vector<float>& row_major);
  const std::string& int64Initializer(const std::string& name, const std::vector<int64_t>& dims,
                                      const std::vector<int64_t>& values);

  // Adds a node named after its (first) output; returns it for attributes.
  onnx::NodeProto& node(const std::string& op_type, const std::vector<std::string>& inputs,
                        const std::string& output);
  // A Constant node giving a float32 tensor: a fixed output of the graph.
  void floatConstant(const std::string& output, const std::vector<int64_t>& dims, const std::vector<float>& row_major);

 private:
  onnx::GraphProto* graph_;
};

void setAttribute(onnx::NodeProto& node, const std::string& name, int64_t value);
void setAttribute(onnx::NodeProto& node, const std::string& name, float value);

}  // namespace masa::onnx_export
