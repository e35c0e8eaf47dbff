// A second runner's command on a robot's command channel, and a witness of what the first runner
// publishes after it (issue #55, item 1), for tests/integration/deploy_sim_robot.sh (cases
// foreign_runner, foreign_runner_signed, safe_stop). It listens on the command channel; the first
// runner id it hears is "the runner". After the runner's --after-th command it publishes one
// command of its own: the runner's last command with --id as its runner_id and a utime 1 us newer
// (so that the runner's next command still wins at the robot), unsigned, or with --roster and
// --signing-key signed as --as (runner 0: a second runner holding the roster's runner key; actor N:
// a key of the roster that may not command). It stops 1 s after the runner fell silent (or at
// --duration) and prints what the runner published after its command:
//   foreign runner: sent 1 command as runner 77 (unsigned) after 60 commands of runner 123
//   foreign runner: runner 123 published 3 commands after it; last: mode 2, sequence 62, kp max 0, kd min 2
// --after -1 sends nothing: the second line then counts every command and describes the last one
// (what a stop left on the wire).
//   masa_test_foreign_runner --after 60 [--id 77] [--roster R --signing-key K --as runner|actor] [--duration S]
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <limits>
#include <memory>
#include <string>

#include "common/transport/channels.hpp"
#include "common/transport/signed_publisher.hpp"
#include "common/transport/transport.hpp"
#include "masa/lcmt_robot_command.hpp"

int main(int argc, char** argv) {
  using namespace masa;
  CLI::App app{"sends one command of a second runner and reports what the first publishes after it (tests)"};
  std::string url, channel = transport::kRobotCommandChannel, roster, key, as = "runner";
  int64_t after = -1, foreign_id = 77;
  double duration = 20;
  app.add_option("--url", url, "LCM provider URL (default: LCM_DEFAULT_URL)");
  app.add_option("--command-channel", channel)->capture_default_str();
  app.add_option("--after", after, "send after this many of the runner's commands (-1: never, only watch)")
      ->capture_default_str();
  app.add_option("--id", foreign_id, "the second runner's runner_id")->capture_default_str();
  auto* roster_opt = app.add_option("--roster", roster, "sign the command with a key of this roster");
  auto* key_opt = app.add_option("--signing-key", key, "the private key to sign with (with --roster)");
  app.add_option("--as", as, "whose key it is: runner (runner 0) or actor (actor 0)")->capture_default_str()
      ->check(CLI::IsMember({"runner", "actor"}));
  app.add_option("--duration", duration, "stop after this many seconds at the latest")->capture_default_str();
  roster_opt->needs(key_opt);
  key_opt->needs(roster_opt);
  CLI11_PARSE(app, argc, argv);
  try {
    std::shared_ptr<transport::MessageSigner> signer;
    if (!roster.empty()) {
      const transport::SenderId id = as == "runner" ? transport::SenderId{transport::Role::kRunner, 0}
                                                    : transport::SenderId{transport::Role::kActor, 0};
      signer = transport::loadSignedMode(roster, key, id).signer;
    }
    transport::Transport lcm(url);
    transport::SignedPublisher out(lcm, signer);
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    Clock::time_point last_heard{};
    int64_t runner = 0, heard = 0, heard_after = 0;
    bool have_runner = false, sent = false;
    lcmt_robot_command cmd, last;
    lcm.subscribeRaw(channel, [&](const void* data, int size) {
      size = transport::sizeWithoutSigTrailer(data, size);  // a witness: the signature is not its business
      if (transport::decodeChecked(data, size, cmd) != transport::WireVerdict::kOk || cmd.runner_id == foreign_id) return;
      if (!have_runner) {
        runner = cmd.runner_id;
        have_runner = true;
      }
      if (cmd.runner_id != runner) return;
      last = cmd;
      last_heard = Clock::now();
      ++heard;
      if (sent) ++heard_after;
      if (after < 0 || sent || heard < after) return;
      lcmt_robot_command foreign = cmd;
      foreign.runner_id = foreign_id;
      foreign.utime = cmd.utime + 1;
      sent = out.publish(channel, foreign);
      if (!sent) return;
      std::printf("foreign runner: sent 1 command as runner %lld (%s) after %lld commands of runner %lld\n",
                  static_cast<long long>(foreign_id), signer ? ("signed as " + signer->id().name()).c_str() : "unsigned",
                  static_cast<long long>(heard), static_cast<long long>(runner));
      std::fflush(stdout);
    });
    for (;;) {
      const auto now = Clock::now();
      if (now - start > std::chrono::duration<double>(duration)) break;
      if (heard > 0 && now - last_heard > std::chrono::seconds(1)) break;
      lcm.handleTimeout(20);
    }
    if (!have_runner) {
      std::printf("foreign runner: heard no runner\n");
      return 1;
    }
    double kp_max = 0, kd_min = std::numeric_limits<double>::infinity();
    for (int k = 0; k < last.num_joints; ++k) {
      kp_max = std::max(kp_max, last.kp[k]);
      kd_min = std::min(kd_min, last.kd[k]);
    }
    std::printf("foreign runner: runner %lld published %lld commands%s; last: mode %d, sequence %lld, kp max %g, kd min %g\n",
                static_cast<long long>(runner), static_cast<long long>(sent ? heard_after : heard),
                sent ? " after it" : "", last.mode, static_cast<long long>(last.sequence), kp_max, kd_min);
    if (after >= 0 && !sent) {
      std::printf("foreign runner: never sent (the runner published %lld commands)\n", static_cast<long long>(heard));
      return 1;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "foreign runner: %s\n", e.what());
    return 2;
  }
  return 0;
}
