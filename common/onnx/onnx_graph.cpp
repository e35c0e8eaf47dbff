#include "common/onnx/onnx_graph.hpp"

#include <cstring>

#include "common/core/check.hpp"

namespace masa::onnx_export {
namespace {

int64_t elementCount(const std::vector<int64_t>& dims) {
  int64_t n = 1;
  for (int64_t d : dims) n *= d;
  return n;
}

void fillValueInfo(onnx::ValueInfoProto* info, const std::string& name, const std::vector<OnnxDim>& dims) {
  info->set_name(name);
  auto* tensor = info->mutable_type()->mutable_tensor_type();
  tensor->set_elem_type(onnx::TensorProto::FLOAT);
  auto* shape = tensor->mutable_shape();
  for (const OnnxDim& d : dims) {
    auto* dim = shape->add_dim();
    if (const auto* size = std::get_if<int64_t>(&d))
      dim->set_dim_value(*size);
    else
      dim->set_dim_param(std::get<std::string>(d));
  }
}

// raw_data is little-endian by the ONNX specification, as on every machine masa builds for.
template <typename T>
void fillTensor(onnx::TensorProto* t, const std::string& name, int data_type, const std::vector<int64_t>& dims,
                const std::vector<T>& values) {
  MASA_CHECK(elementCount(dims) == static_cast<int64_t>(values.size()),
             "tensor '" << name << "' has " << values.size() << " values for " << elementCount(dims) << " elements");
  t->set_name(name);
  t->set_data_type(data_type);
  for (int64_t d : dims) t->add_dims(d);
  std::string bytes(values.size() * sizeof(T), '\0');
  if (!values.empty()) std::memcpy(bytes.data(), values.data(), bytes.size());
  t->set_raw_data(std::move(bytes));
}

}  // namespace

void OnnxGraph::input(const std::string& name, const std::vector<OnnxDim>& dims) {
  fillValueInfo(graph_->add_input(), name, dims);
}

void OnnxGraph::output(const std::string& name, const std::vector<OnnxDim>& dims) {
  fillValueInfo(graph_->add_output(), name, dims);
}

const std::string& OnnxGraph::floatInitializer(const std::string& name, const std::vector<int64_t>& dims,
                                               const std::vector<float>& row_major) {
  onnx::TensorProto* t = graph_->add_initializer();
  fillTensor(t, name, onnx::TensorProto::FLOAT, dims, row_major);
  return t->name();
}

const std::string& OnnxGraph::int64Initializer(const std::string& name, const std::vector<int64_t>& dims,
                                               const std::vector<int64_t>& values) {
  onnx::TensorProto* t = graph_->add_initializer();
  fillTensor(t, name, onnx::TensorProto::INT64, dims, values);
  return t->name();
}

onnx::NodeProto& OnnxGraph::node(const std::string& op_type, const std::vector<std::string>& inputs,
                                 const std::string& output) {
  onnx::NodeProto* n = graph_->add_node();
  n->set_op_type(op_type);
  n->set_name(output);
  for (const std::string& in : inputs) n->add_input(in);
  n->add_output(output);
  return *n;
}

void OnnxGraph::floatConstant(const std::string& output, const std::vector<int64_t>& dims,
                              const std::vector<float>& row_major) {
  onnx::AttributeProto* value = node("Constant", {}, output).add_attribute();
  value->set_name("value");
  value->set_type(onnx::AttributeProto::TENSOR);
  fillTensor(value->mutable_t(), output, onnx::TensorProto::FLOAT, dims, row_major);
}

void setAttribute(onnx::NodeProto& node, const std::string& name, int64_t value) {
  onnx::AttributeProto* a = node.add_attribute();
  a->set_name(name);
  a->set_type(onnx::AttributeProto::INT);
  a->set_i(value);
}

void setAttribute(onnx::NodeProto& node, const std::string& name, float value) {
  onnx::AttributeProto* a = node.add_attribute();
  a->set_name(name);
  a->set_type(onnx::AttributeProto::FLOAT);
  a->set_f(value);
}

}  // namespace masa::onnx_export
