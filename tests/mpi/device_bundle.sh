#!/usr/bin/env bash
# The bundle of bench/device_bundle.sh trains on a machine without our packages: with the system's
# Open MPI, PMIx and every library the bundle carries hidden (bind mounts in a private mount
# namespace), 2 learner ranks and 2 actors run 3 updates from the bundle alone. This is how the
# device machine of issue #30 (no network, none of our Debian packages) ran the scaling tables.
# Skipped (77) where a mount namespace cannot be made (not root, no unshare).
#   tests/mpi/device_bundle.sh BUILD_DIR
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-build}" && pwd)
cd "$repo"
[ "$(id -u)" = 0 ] && command -v unshare > /dev/null && unshare -m true 2> /dev/null ||
  { echo "SKIP: needs root and unshare -m (a mount namespace to hide the system's libraries)"; exit 77; }
work=$(mktemp -d /tmp/masa_device_bundle.XXXXXX)
trap 'rm -rf "$work"' EXIT
bash bench/device_bundle.sh --build "$build" --out "$work/bundle" --programs "learner/masa_learner actors/masa_actor tools/masa_config" ||
  { echo "FAIL: device_bundle.sh"; exit 1; }
# Inside the namespace: the system's copies hidden, then only the bundle's environment. The tools
# the scripts use (grep, sed, mkdir) link libraries the bundle also carries, so they run after
# env.sh, as on the device.
unshare -m python3 tests/integration/hide_system_libraries.py "$work/bundle" bash -c '
  set -euo pipefail
  source "$1/env.sh"
  ldd "$MASA_BUILD_DIR/learner/masa_learner" | grep -q "libmpi.so.40 => $1/lib/" || { echo "FAIL: libmpi not from the bundle"; exit 1; }
  if LD_LIBRARY_PATH= "$MASA_BUILD_DIR/learner/masa_learner" --help > /dev/null 2>&1; then
    echo "FAIL: the learner ran without the bundle: nothing was hidden"; exit 1
  fi
  MASA_LCM_URL="udpm://239.255.76.67:7733?ttl=0&recv_buf_size=8388608" bench/e2e_ranks.sh a1_beam --ranks 2 --actors 2 --envs 16 --updates 3 --warmup 1 --out "$2/e2e" \
    --set model.policy_hidden=[16] --set model.critic_hidden=[16]
' _ "$work/bundle" "$work" > "$work/run.log" 2>&1 || { tail -n 30 "$work/run.log"; tail -n 30 "$work/e2e/train.log" 2> /dev/null; echo "FAIL: the bundle did not train"; exit 1; }
grep -q "ranks 2 actors 2 x 16 envs.*fps [0-9]" "$work/run.log" || { cat "$work/run.log"; echo "FAIL: no fps line"; exit 1; }
rows=$(($(wc -l < "$work/e2e/run/metrics.csv") - 1))
[ "$rows" = 3 ] || { echo "FAIL: $rows updates, not 3"; exit 1; }
grep "e2e_ranks" "$work/run.log"
echo "PASS: 2 ranks and 2 actors trained 3 updates from the bundle with the system's Open MPI and libraries hidden"
