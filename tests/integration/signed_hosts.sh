#!/usr/bin/env bash
# How deploy/train.sh --hosts distributes a signed run's keys (issue #33, item 2): a "remote" host
# that is this machine through a stand-in remote shell (MASA_REMOTE_SHELL runs the command with bash
# in a MASA_REMOTE_DIR of its own, which links this repository's deploy/ and build/), and localhost.
# Passes when the run trains, the remote host's run directory holds the roster and the key of its own
# actor (actor 0) only, mode 0600, never the learner's or actor 1's, and both actors signed with their
# own keys. The launcher's keys are in MASA_KEYS_DIR, a directory outside the run directory (as a
# host's own disk is when the run directory is on a shared file system; issue #55, item 4): the
# run directory here must hold no private key, the learner and actor 1 sign with the keys there.
#   MASA_BUILD_DIR=build bash tests/integration/signed_hosts.sh [PORT]
# Prints PASS and exits 0, or FAIL with the logs' tails and exits 1. About 10-30 s.
set -euo pipefail
cd "$(dirname "$0")/../.."
source tests/integration/lib.sh

port=${1:-7721}
begin_local_run signed_hosts "$port"
url="udpm://239.255.77.179:$port?ttl=0"
remote="$work/remote"
mkdir -p "$remote"
ln -s "$masa_repo/deploy" "$remote/deploy"
ln -s "$build" "$remote/build"
printf '#!/usr/bin/env bash\nshift\nexec bash -c "$1"\n' > "$work/remote_shell"
chmod +x "$work/remote_shell"
printf 'remotehost 1 8\nlocalhost 1 8\n' > "$work/hosts"
# A run directory relative to the repository, so that the remote host's is under MASA_REMOTE_DIR.
rel="runs/test_signed_hosts_$$_$(date +%s%N)"
trap 'kill_started; rm -rf "$rel"' EXIT

log "train.sh --hosts: actor 0 on a stand-in remote host, actor 1 here, on $url (work dir $work)"
keys_dir="$work/host_keys"
MASA_BUILD_DIR=$build MASA_KEYS_DIR=$keys_dir MASA_REMOTE_DIR=$remote MASA_REMOTE_BUILD_DIR=build MASA_REMOTE_SHELL="$work/remote_shell" \
  MASA_LCM_URL=$url bash deploy/train.sh a1_beam masa --hosts "$work/hosts" --updates 3 --run-dir "$rel" \
  --set model.policy_hidden=[16] --set model.critic_hidden=[16] --set ppo.minibatch_size=256 \
  --set runner.eval_every=0 > "$work/train.log" 2>&1 || fail "train.sh failed"

grep -q "stopped after 3 updates" "$work/train.log" || fail "the run did not make its 3 updates"
there=$(cd "$remote/$rel" && find . -type f | sort | tr '\n' ' ')
[ "$there" = "./keys/actor0.key ./roster " ] || fail "the remote host holds '$there', not the roster and actor 0's key alone"
[ "$(stat -c %a "$remote/$rel/keys/actor0.key")" = 600 ] || fail "the carried key is not mode 0600"
cmp -s "$remote/$rel/roster" "$rel/roster" || fail "the carried roster differs"
grep -q "actor 0: messages signed with $rel/keys/actor0.key" "$rel/actor0.log" || fail "actor 0 did not sign with its key"
grep -q "actor 1: messages signed with $keys_dir/actor1.key" "$rel/actor1.log" || fail "actor 1 did not sign with its key in MASA_KEYS_DIR"
grep -qs "messages signed with $keys_dir/learner0.key" "$rel/learner.log" "$work/train.log" || fail "the learner did not sign with its key in MASA_KEYS_DIR"
here=$(find "$rel" -name '*.key')
[ -z "$here" ] || fail "private keys in the run directory, with MASA_KEYS_DIR given: $here"
echo "PASS: 3 signed updates; the remote host got the roster and actor 0's key (0600) only; no private key in the run directory"
rm -rf "$work"
