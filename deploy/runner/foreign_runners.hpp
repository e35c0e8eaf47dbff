// Commands of other runners on this runner's command channel (issue #55, item 3). Two runners
// commanding one robot fight over it: the start guard refuses to start beside one, and a runner
// that appears later stops this one, with the safe command first (runner_main.cpp).
//
// Heard unverified (no roster), any well-formed command with another runner_id counts, signed or
// not (a signing runner's trailer is cut off unchecked): it errs towards stopping, and anyone on
// the robot's LAN can stop the runner with one datagram, safely. Heard through a transport that
// verifies against the roster (masa_deploy --roster), only a command a sender of the roster may
// publish on the channel signed, with a new counter, reaches this listener: the others are refused
// and counted by that transport (Transport::rejectSummary) and change nothing here.
#pragma once

#include <cstdint>
#include <string>

#include "common/transport/transport.hpp"
#include "masa/lcmt_robot_command.hpp"

namespace masa::deploy {

class ForeignRunners {
 public:
  // Listens on `channel` of `from` for commands whose runner_id is not `own_id`. `sized` is a command
  // sized for this robot (PolicyRunner::makeCommand), so that decoding one allocates nothing.
  // Verified when `from` authenticates (its handlers see only messages that passed).
  void listen(transport::Transport& from, const std::string& channel, const masa::lcmt_robot_command& sized,
              int64_t own_id);

  bool verified() const { return verified_; }
  // Well-formed commands of another runner (verified, when verified()).
  int64_t heard() const { return heard_; }
  int64_t lastId() const { return last_id_; }
  // Messages on the channel the wire guard refused (after the signature checks, when verified()).
  int64_t undecodable() const { return undecodable_; }

 private:
  masa::lcmt_robot_command scratch_;  // what the guard decodes into; read only when it passed
  bool verified_ = false;
  int64_t heard_ = 0, last_id_ = 0, undecodable_ = 0;
};

}  // namespace masa::deploy
