// A hostile machine beside a robot whose commands (or state) are signed (issue #33, item 2), for
// tests/integration/deploy_sim_robot.sh (cases signed_commands and signed_state). For every new
// command the runner signs (a SIG1 trailer naming runner 0) it hears, it sends
//   - the same bytes again (a replay) ............................................ replayed
//   - the command changed (an emergency stop, mode 4, targets +0.3 rad, 10 s newer than the runner's
//     so that it would win), signed with the key it holds, a key of the roster that may not command
//     the robot (an actor's) ............................................................ not_permitted
//   - the same changed command unsigned ............................................... unauthenticated
// and at the end prints how many of each. A robot that took any changed command spends physics
// steps in mode 4. The runner id stays the runner's, so that what is tested is the robot's
// verification: the signing runner refuses these too (unauthenticated, not_permitted, replayed:
// its stop line), and another runner_id on them would not stop it (deploy_sim_robot.sh
// foreign_runner_signed).
// With --state, the same for every new state message robot 0 signs: the replay, and the state
// changed (NaN joint angles, or every other time the base rolled by 1 rad; utime 1 ms newer)
// signed with the actor's key and unsigned. A runner that took a changed state leaves its policy:
// NaN angles give the safe command, the roll the emergency stop.
// With --future (no key needed), beside a runner signed or not: for every new command of the runner
// it hears, the command changed as above (an emergency stop, 10 s newer) and unsigned, nothing else:
// a robot that takes unsigned commands (--insecure) must refuse it by its clock (ahead_of_clock),
// or it applies it until the runner's clock catches up, 10 s later (issue #55, item 2).
//   masa_test_robot_message_forger --roster DIR/roster --signing-key DIR/keys/actor0.key --actor 0 --duration S [--state]
//   masa_test_robot_message_forger --future --duration S
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <vector>

#include "common/transport/channels.hpp"
#include "common/transport/signed_publisher.hpp"
#include "common/transport/transport.hpp"
#include <limits>

#include "masa/lcmt_robot_command.hpp"
#include "masa/lcmt_robot_state.hpp"

namespace {

// --future: every new command of the runner (signed or not; not this forger's own, which are 10 s
// ahead) sent again changed and unsigned, stamped 10 s ahead.
int forgeFuture(const std::string& url, const std::string& channel, double duration) {
  using namespace masa;
  transport::Transport lcm(url);
  int64_t sent = 0, newest = 0;
  lcm.subscribeRaw(channel, [&](const void* data, int size) {
    lcmt_robot_command cmd;
    const int body = transport::sizeWithoutSigTrailer(data, size);
    if (transport::decodeChecked(data, body, cmd) != transport::WireVerdict::kOk) return;
    if (cmd.utime <= newest || cmd.utime > transport::wallClockMicros() + 1000000) return;
    newest = cmd.utime;
    cmd.mode = 4;
    cmd.utime += 10000000;
    for (auto& p : cmd.position) p += 0.3;
    if (lcm.publish(channel, cmd)) ++sent;
  });
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration);
  while (std::chrono::steady_clock::now() < end) lcm.handleTimeout(20);
  std::printf("robot command forger: %lld unsigned commands 10 s in the future\n", static_cast<long long>(sent));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace masa;
  CLI::App app{"forges robot commands (or state) beside a signing runner (or robot) (tests)"};
  std::string url, roster, key, channel = transport::kRobotCommandChannel, state_channel = transport::kRobotStateChannel;
  bool state = false, future = false;
  uint32_t actor = 0;
  double duration = 5;
  app.add_option("--url", url, "LCM provider URL (default: LCM_DEFAULT_URL)");
  app.add_option("--roster", roster, "the roster that lists the key");
  app.add_option("--signing-key", key, "a private key of the roster that is not the runner's");
  app.add_option("--actor", actor, "the key's actor index in the roster")->capture_default_str();
  app.add_option("--duration", duration, "seconds")->capture_default_str();
  app.add_option("--command-channel", channel)->capture_default_str();
  app.add_option("--state-channel", state_channel)->capture_default_str();
  app.add_flag("--state", state, "forge robot 0's state messages instead of the runner's commands");
  app.add_flag("--future", future, "send only the changed command, unsigned, 10 s ahead of the runner's");
  CLI11_PARSE(app, argc, argv);
  if (!future && (roster.empty() || key.empty())) {
    std::fprintf(stderr, "robot message forger: --roster and --signing-key, or --future\n");
    return 2;
  }
  try {
    if (future) return forgeFuture(url, channel, duration);
    auto signer = transport::loadSignedMode(roster, key, {transport::Role::kActor, actor}).signer;
    transport::Transport lcm(url);
    transport::SignedPublisher as_actor(lcm, signer);
    int64_t replays = 0, actor_signed = 0, unsigned_sent = 0;
    uint64_t newest = 0;
    std::vector<uint8_t> copy;
    // Only the signer's new messages: not this forger's own copies coming back.
    const transport::Role victim = state ? transport::Role::kRobot : transport::Role::kRunner;
    const std::string& on = state ? state_channel : channel;
    lcm.subscribeRaw(on, [&](const void* data, int size) {
      transport::SenderId sender;
      uint64_t counter = 0;
      if (!transport::peekSigner(data, size, sender, counter) || sender.role != victim || counter <= newest) return;
      newest = counter;
      copy.assign(static_cast<const uint8_t*>(data), static_cast<const uint8_t*>(data) + size);
      const int body = size - transport::kSigTrailerBytes;
      if (state) {
        lcmt_robot_state st;
        if (transport::decodeChecked(copy.data(), body, st) != transport::WireVerdict::kOk) return;
        if (lcm.publishWire(on, copy.data(), size)) ++replays;
        // 1 ms newer: inside the freshness lead, so that a runner that does not verify takes it.
        st.utime += 1000;
        // Every other one NaN joint angles, the others a base rolled by 1 rad (a fall, to an IMU).
        if (replays % 2 == 0) {
          for (auto& q : st.joint_position) q = std::numeric_limits<double>::quiet_NaN();
        } else {
          st.has_base = 1;
          st.base_qw = std::cos(0.5);
          st.base_qx = std::sin(0.5);
          st.base_qy = st.base_qz = 0;
        }
        if (as_actor.publish(on, st)) ++actor_signed;
        if (lcm.publish(on, st)) ++unsigned_sent;
        return;
      }
      lcmt_robot_command cmd;
      if (transport::decodeChecked(copy.data(), body, cmd) != transport::WireVerdict::kOk) return;
      if (lcm.publishWire(on, copy.data(), size)) ++replays;
      cmd.mode = 4;
      cmd.utime += 10000000;
      for (auto& p : cmd.position) p += 0.3;
      if (as_actor.publish(on, cmd)) ++actor_signed;
      if (lcm.publish(on, cmd)) ++unsigned_sent;
    });
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(duration);
    while (std::chrono::steady_clock::now() < end) lcm.handleTimeout(20);
    const char* what = state ? "state" : "command";
    std::printf("robot %s forger: %lld replays, %lld %ss signed by actor %u, %lld unsigned\n", what,
                static_cast<long long>(replays), static_cast<long long>(actor_signed), what, actor,
                static_cast<long long>(unsigned_sent));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robot message forger: %s\n", e.what());
    return 2;
  }
  return 0;
}
