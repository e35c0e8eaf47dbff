#include "common/symmetry/symmetry_spec.hpp"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/core/config_error.hpp"
#include "common/symmetry/spec_compiler.hpp"
#include "common/symmetry/spec_parser.hpp"

namespace masa::sym {
namespace {

int blockDim(const std::vector<Entry>& entries) {
  int d = 0;
  for (const Entry& e : entries) d += e.size();
  return d;
}

}  // namespace

int BlockLayout::centralDim() const { return blockDim(central); }
int BlockLayout::limbDim() const { return blockDim(limb); }

SymmetrySpec SymmetrySpec::load(const std::string& yaml_path) {
  std::ifstream in(yaml_path);
  if (!in) {
    const bool exists = std::filesystem::exists(yaml_path);
    throw ConfigError(yaml_path, "<file>", exists ? "cannot read the file" : "file does not exist");
  }
  std::stringstream text;
  text << in.rdbuf();
  return parseString(text.str(), yaml_path);
}

SymmetrySpec SymmetrySpec::parseString(const std::string& yaml_text, const std::string& source_name) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::ParserException& e) {
    // yaml-cpp's marks are 0-based.
    throw ConfigError(source_name, "<yaml>",
                      "YAML syntax error at line " + std::to_string(e.mark.line + 1) + ", column " +
                          std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
  return parse(root, source_name);
}

SymmetrySpec SymmetrySpec::parse(const YAML::Node& root, const std::string& source_name) {
  ParsedSpec parsed = parseSpecYaml(root, source_name);
  SymmetrySpec spec;
  spec.name_ = std::move(parsed.name);
  spec.source_ = source_name;
  spec.group_ = parsed.group;
  spec.obs_ = std::move(parsed.observation);
  spec.act_ = std::move(parsed.action);
  spec.mujoco_ = std::move(parsed.mujoco);
  const int n = spec.numAgents();
  for (int i = 0; i < n; ++i) {
    spec.obs_t_.push_back(compileTransform(spec.obs_, spec.group_, i));
    spec.act_t_.push_back(compileTransform(spec.act_, spec.group_, i));
  }
  spec.obs_classes_ = orbitClasses(spec.obs_t_, spec.obsDim());
  spec.act_classes_ = orbitClasses(spec.act_t_, spec.actDim());
  spec.obs_names_ = dimensionNames(spec.obs_, n);
  spec.act_names_ = dimensionNames(spec.act_, n);
  return spec;
}

int SymmetrySpec::obsDim() const { return obs_.centralDim() + numAgents() * obs_.limbDim(); }
int SymmetrySpec::actDim() const { return act_.centralDim() + numAgents() * act_.limbDim(); }

std::vector<std::string> SymmetrySpec::actuatorsInActionOrder() const {
  if (!mujoco_.present) throw ConfigError(source_, "mujoco", "this spec has no mujoco section binding actions to actuators");
  std::vector<std::string> names = mujoco_.central_actuators;
  for (const auto& limb : mujoco_.limb_actuators) names.insert(names.end(), limb.begin(), limb.end());
  return names;
}

const SparseMap& SymmetrySpec::obsTransform(int i) const {
  MASA_CHECK(i >= 0 && i < numAgents(), "agent " << i << " outside [0, " << numAgents() << ")");
  return obs_t_[i];
}

const SparseMap& SymmetrySpec::actTransform(int i) const {
  MASA_CHECK(i >= 0 && i < numAgents(), "agent " << i << " outside [0, " << numAgents() << ")");
  return act_t_[i];
}

}  // namespace masa::sym
