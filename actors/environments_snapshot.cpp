#include "actors/environments_snapshot.hpp"

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

namespace masa::actor {
namespace {
constexpr const char* kHeader = "masa actor environments 1";
}  // namespace

void EnvironmentsSnapshot::take(const Actor& actor, int64_t update) {
  std::ostringstream out;
  actor.saveEnvironments(out);
  bytes_ = std::move(out).str();
  update_ = update;
}

void EnvironmentsSnapshot::writeIfAt(int64_t update, const std::string& path) const {
  if (update != update_) return;  // (the learner's checkpoint and the actor would not agree)
  std::ostringstream out(std::ios::binary);
  out << kHeader << "\n" << update_ << "\n";
  out.write(bytes_.data(), static_cast<std::streamsize>(bytes_.size()));
  integrity::writeSealedFile(path, kEnvironmentsFileKind, out.view());
}

std::string resumeEnvironments(const std::string& path, int64_t update, Actor& actor) {
  if (!std::filesystem::exists(path)) return "no " + std::filesystem::path(path).filename().string();
  std::istringstream in(integrity::readSealedFile(path, kEnvironmentsFileKind).payload, std::ios::binary);
  std::string header;
  std::string update_line;
  std::getline(in, header);
  std::getline(in, update_line);
  if (header != kHeader) throw std::runtime_error(path + ": not a masa actor's environments (its first line is not '" + kHeader + "')");
  int64_t saved = -1;
  try {
    std::size_t used = 0;
    saved = std::stoll(update_line, &used);
    if (used != update_line.size()) throw std::invalid_argument("trailing text");
  } catch (const std::exception&) {
    throw std::runtime_error(path + ": its update line '" + update_line + "' is not a number");
  }
  if (saved != update)
    return std::filesystem::path(path).filename().string() + " is of update " + std::to_string(saved) + ", the checkpoint of " +
           std::to_string(update);
  try {
    actor.loadEnvironments(in);
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  return "";
}

}  // namespace masa::actor
