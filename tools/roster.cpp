// masa_roster: the keys and the roster of a signed run (common/transport/roster.hpp, message_sign.hpp).
//   masa_roster make RUN_DIR --actors K [--runner] [--robot]
//                                                   a key per process, RUN_DIR/keys/<role><index>.key
//                                                   (mode 0600, directory 0700), and RUN_DIR/roster
//                                                   with their public keys and the channels of each role
//   masa_roster make RUN_DIR --keys DIR ...          the private keys (and their .pub) in DIR instead, a
//                                                   directory on this host's own disk: a run directory on
//                                                   a file system every host mounts then holds the roster
//                                                   and no private key (issue #55, item 4)
//   masa_roster show ROSTER                          the senders, their key fingerprints and channels
// make keeps what is there: a resumed run keeps its keys, and more actors get keys of their own. It
// keeps only what it wrote (issue #55, item 4): every line of an existing roster must carry the
// public key of RUN_DIR/keys/<role><index>.key and its role's channels; a line no key file of ours
// backs (one someone planted, or a key swapped) is refused with the line named, never adopted.
// With --actors given, actors beyond K leave the roster, their key files removed (issue #55, item 3): a run resumed with
// fewer actors must not go on believing the ones it no longer runs, whose hosts still hold their
// keys and whose recorded chunks would verify as current data. Brought back later, an actor index
// gets a new key.
// deploy/train.sh runs it before it starts anything and gives each process its own key file; the
// private keys stay files, never on a command line.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <sys/stat.h>

#include "common/core/build_info.hpp"
#include "common/integrity/ed25519_keys.hpp"
#include "common/transport/roster.hpp"

using namespace masa;
namespace fs = std::filesystem;

namespace {

void writeRoster(const transport::Roster& roster, const fs::path& path) {
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << roster.format();
    if (!out) throw std::runtime_error(tmp.string() + ": cannot write");
  }
  ::chmod(tmp.c_str(), 0644);
  fs::rename(tmp, path);  // appears whole
}

// The roster without actors of index `actors` and above, and their key files removed; returns how
// many left.
int retireActorsFrom(transport::Roster& roster, int actors, const fs::path& keys) {
  std::vector<transport::SenderId> retired;
  roster = roster.withoutActorsFrom(static_cast<uint32_t>(actors), retired);
  for (const transport::SenderId& id : retired) {
    const std::string stem = (keys / ("actor" + std::to_string(id.index))).string();
    fs::remove(stem + ".key");
    fs::remove(stem + ".pub");
    std::printf("masa_roster: %s retired (the run has %d actors): it leaves the roster\n", id.name().c_str(), actors);
  }
  return static_cast<int>(retired.size());
}

std::string keyStem(const fs::path& keys, transport::SenderId id) {
  return (keys / (std::string(transport::roleName(id.role)) + std::to_string(id.index))).string();
}

// Throws unless every entry is one make wrote: its private key file is here, checked as any key
// (owner, mode, directory), it gives the entry's public key, and the entry has its role's channels.
void refuseEntriesNotOurs(const transport::Roster& roster, const fs::path& keys) {
  for (const transport::Roster::Entry& e : roster.entries()) {
    const std::string key_path = keyStem(keys, e.id) + ".key";
    const std::string planted = "roster " + roster.source() + ": the line of " + e.id.name() + " (" +
                                integrity::keyFingerprint(e.key) + ") is not one masa_roster wrote: ";
    const std::string advice = "; a roster line masa_roster did not write is never adopted (remove the line, or the "
                               "roster and keys to start afresh)";
    if (!fs::exists(key_path)) throw std::runtime_error(planted + "there is no private key " + key_path + advice);
    const integrity::SigningKey key = integrity::SigningKey::load(key_path);
    if (key.publicKey() != e.key)
      throw std::runtime_error(planted + "its key is not the one of " + key_path + " (" +
                               integrity::keyFingerprint(key.publicKey()) + ")" + advice);
    if (e.channels != transport::defaultChannels(e.id.role))
      throw std::runtime_error(planted + "its channels are not those masa_roster gives " +
                               std::string(transport::roleName(e.id.role)) + "s" + advice);
  }
}

int make(const std::string& dir, const std::string& keys_dir, int actors, bool actors_given, bool runner, bool robot) {
  const fs::path run(dir), keys = keys_dir.empty() ? run / "keys" : fs::path(keys_dir), roster_path = run / "roster";
  fs::create_directories(run);
  fs::create_directories(keys);
  ::chmod(keys.c_str(), 0700);
  transport::Roster roster;
  if (fs::exists(roster_path)) roster = transport::Roster::load(roster_path.string());
  {
    // What stays is checked before anything is removed: a refused roster leaves the keys as they were.
    std::vector<transport::SenderId> leaving;
    refuseEntriesNotOurs(actors_given ? roster.withoutActorsFrom(static_cast<uint32_t>(actors), leaving) : roster, keys);
  }
  const int retired = actors_given ? retireActorsFrom(roster, actors, keys) : 0;
  std::vector<transport::SenderId> wanted = {{transport::Role::kLearner, 0}};
  for (int a = 0; a < actors; ++a) wanted.push_back({transport::Role::kActor, static_cast<uint32_t>(a)});
  if (runner) wanted.push_back({transport::Role::kRunner, 0});
  if (robot) wanted.push_back({transport::Role::kRobot, 0});
  int made = 0;
  for (const transport::SenderId& id : wanted) {
    if (roster.find(id)) continue;
    const std::string stem = keyStem(keys, id);
    const integrity::PublicKeyBytes key = integrity::generateKeyPair(stem + ".key", stem + ".pub");
    roster.add(id, key, transport::defaultChannels(id.role));
    ++made;
  }
  if (made > 0 || retired > 0) writeRoster(roster, roster_path);
  std::printf("masa_roster: %s: %zu senders (%d new keys under %s, %d actors retired)\n", roster_path.c_str(),
              roster.entries().size(), made, keys.c_str(), retired);
  return 0;
}

int show(const std::string& path) {
  const transport::Roster roster = transport::Roster::load(path);
  for (const auto& e : roster.entries()) {
    std::printf("%-10s %s ", e.id.name().c_str(), integrity::keyFingerprint(e.key).c_str());
    for (std::size_t i = 0; i < e.channels.size(); ++i) std::printf("%s%s", i ? "," : "", e.channels[i].c_str());
    std::printf("\n");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"masa_roster: a key per process and the roster of a signed run"};
  app.set_version_flag("--version", buildCommit());
  app.require_subcommand(1);
  std::string dir, path, keys_dir;
  int actors = 1;
  bool runner = false, robot = false;
  auto* make_cmd = app.add_subcommand("make", "make the keys and the roster of a run directory (keeps what is there)");
  make_cmd->add_option("run_dir", dir, "the run directory")->required();
  auto* actors_opt = make_cmd->add_option("--actors", actors, "actors of the run (keys actor0 .. actorK-1); actors beyond "
                                          "leave the roster")->check(CLI::Range(0, 1 << 20));
  make_cmd->add_option("--keys", keys_dir, "where the private keys go (default RUN_DIR/keys): a directory on this host's "
                       "own disk when RUN_DIR is on a file system other hosts mount; give the same one each time");
  make_cmd->add_flag("--runner", runner, "a key for the robot's policy runner (masa_deploy), on the robot command channel");
  make_cmd->add_flag("--robot", robot, "a key for the robot (masa_sim_robot --signing-key), on the robot state channel");
  auto* show_cmd = app.add_subcommand("show", "the senders of a roster");
  show_cmd->add_option("roster", path, "a roster file")->required();
  CLI11_PARSE(app, argc, argv);
  try {
    if (*make_cmd) return make(dir, keys_dir, actors, actors_opt->count() > 0, runner, robot);
    return show(path);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "masa_roster: %s\n", e.what());
    return 2;
  }
}
