#!/usr/bin/env bash
# One call of the device machine for issue #30, on a bare machine with the bundle of
# bench/device_bundle.sh: set-up (loopback multicast, socket buffers, the bundle's programs and
# Open MPI), a smoke test that stops early with its logs if the bundle does not run there (so the
# device time left can pay for a corrected try), then bench/scaling_device.sh under a time limit.
# What comes back fits the device tool's limits (8 files, 2 folders deep): the tables as text and
# everything else in one archive.
#   bench/device_session.sh [--bundle DIR] [--limit SECONDS] [--out OUT] [-- scaling_device.sh options]
#                           (default .device, 470, $OUT)
set -uo pipefail
cd "$(dirname "$0")/.."
bundle=.device limit=470 out=${OUT:-/tmp/masa_device_session} pass=()
while [ $# -gt 0 ]; do
  case "$1" in
    --bundle) bundle=$2; shift 2 ;;
    --limit) limit=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --) shift; pass=("$@"); break ;;
    *) echo "device_session.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
mkdir -p "$out"
log=$out/session.txt work=/tmp/masa_device_work
rm -rf "$work"; mkdir -p "$work"
exec > >(tee -a "$log") 2>&1
start=$SECONDS
pack() {  # the archive of everything but checkpoints and environments, and the tables beside it
  tar -C "$work" --exclude='*.bin' --exclude='*.key' -czf "$out/scaling_device.tar.gz" . 2> /dev/null
  for f in learner_ranks.txt actors.txt ranks.txt probe.txt model.txt points.txt check/check.txt; do
    [ -f "$work/$f" ] && cp "$work/$f" "$out/$(basename "$f")"
  done
  echo "device_session.sh: $((SECONDS - start)) s; back: $(ls "$out" | tr '\n' ' ')"
}

echo "# $(date -u +%FT%TZ) bundle of $(cat "$bundle/COMMIT" 2> /dev/null || echo '?')"
echo "# $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), \
$(grep -o -w -m1 -E 'avx512f' /proc/cpuinfo || echo 'no avx512f'), $(. /etc/os-release 2> /dev/null && echo "$PRETTY_NAME"), load $(cut -d' ' -f1-3 /proc/loadavg)"
# Loopback multicast: LCM asks for 8 MB receive buffers, and needs a route for the group.
sysctl -q -w net.core.rmem_max=8388608 net.core.rmem_default=2097152 || echo "sysctl failed: LCM keeps small buffers"
if command -v ip > /dev/null && ! ip route get 239.255.76.67 > /dev/null 2>&1; then
  ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo && echo "multicast routed over lo"
fi
real_python=$(command -v python3)
# shellcheck disable=SC1091
source "$bundle/env.sh"
# Python keeps the machine's own libraries (the bundle's older ones could break its modules).
mkdir -p "$work/pybin"
printf '#!/bin/sh\nunset LD_LIBRARY_PATH\nexec %s "$@"\n' "$real_python" > "$work/pybin/python3"
chmod +x "$work/pybin/python3"
export PATH="$work/pybin:$PATH"

echo "--- smoke: 2 learner ranks; then 1 rank and 2 actors over loopback multicast"
if ! timeout 60 tests/mpi/mpirun.sh -np 2 -x OMP_NUM_THREADS=1 "$MASA_BUILD_DIR/bench/bench_learner_ranks" --recipe a1_beam --updates 1 ||
  ! timeout 90 bench/e2e_ranks.sh a1_beam --ranks 1 --actors 2 --envs 32 --updates 3 --warmup 1 --out "$work/smoke"; then
  echo "device_session.sh: the smoke test failed; its logs follow"
  tail -n 40 "$work/smoke/train.log" 2> /dev/null
  ldd "$MASA_BUILD_DIR/learner/masa_learner" | grep 'not found'
  pack
  exit 1
fi

echo "--- bench/scaling_device.sh, at most $limit s"
timeout -k 10 "$limit" bench/scaling_device.sh --out "$work" "${pass[@]+"${pass[@]}"}" || echo "device_session.sh: scaling_device.sh ended with status $? (124: the time limit)"
pkill -f masa_learner; pkill -f masa_actor; pkill -f orterun
pack
