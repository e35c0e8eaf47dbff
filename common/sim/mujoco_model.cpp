#include "common/sim/mujoco_model.hpp"

#include <filesystem>
#include <stdexcept>

namespace masa::task {

std::shared_ptr<MujocoModel> MujocoModel::load(const std::string& path) {
  if (!std::filesystem::exists(path)) throw std::runtime_error(path + ": model file not found");
  char error[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
  if (!m) throw std::runtime_error(path + ": MuJoCo could not load the model: " + error);
  return std::shared_ptr<MujocoModel>(new MujocoModel(m, path));
}

MujocoModel::~MujocoModel() { mj_deleteModel(m_); }

int MujocoModel::id(int type, const std::string& name) const {
  const int i = mj_name2id(m_, type, name.c_str());
  if (i < 0) {
    const char* type_name = mju_type2Str(type);
    throw std::runtime_error(path_ + ": no " + std::string(type_name ? type_name : "object") + " named '" + name + "'");
  }
  return i;
}

std::shared_ptr<MujocoModel> MujocoModel::clone() const {
  return std::shared_ptr<MujocoModel>(new MujocoModel(mj_copyModel(nullptr, m_), path_));
}

}  // namespace masa::task
