#!/usr/bin/env bash
# Updates per minute of a training run over a lossy LAN (issue #9's targets): the learner and two
# actors on three network namespaces (tests/integration/netns_hosts.sh), nftables dropping 0, 5 and
# 20% of the rollout datagrams that reach the learner's host, in one run of this script; with
# --everywhere, of every datagram that reaches any host from another, in both directions
# (parameters, rollouts, heartbeats), as a lossy switch or Wi-Fi does. Each level trains N updates
# of the test's small configuration (a1_beam, [16] networks; --full-model: issue #33's, the default
# networks and 2 x 32 environments); the rate is taken after the first 5.
# Last lines: "retained at 5% X" and "retained at 20% Y" (of the 0% rate; targets 0.85 and 0.50).
# Needs root, iproute2 and nftables.
#   MASA_BUILD_DIR=build bench/e2e_loss.sh [--everywhere] [--full-model] [--updates N] [--levels "0 5 20"] [--port PORT]
set -euo pipefail
cd "$(dirname "$0")/.."
updates=150 levels="0 5 20" port=7698 where=()
while [ $# -gt 0 ]; do
  case "$1" in
    --everywhere) where+=(--everywhere); shift ;;
    --full-model) where+=(--full-model); shift ;;
    --updates) updates=$2; shift 2 ;;
    --levels) levels=$2; shift 2 ;;
    --port) port=$2; shift 2 ;;
    *) echo "e2e_loss.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
echo "e2e_loss: $([[ " ${where[*]-} " == *" --everywhere "* ]] && echo "loss everywhere" || echo "loss of rollouts to the learner")$([[ " ${where[*]-} " == *" --full-model "* ]] && echo ", default networks, 2 x 32 envs" || true), $(date -u +%FT%TZ), commit $(git rev-parse --short HEAD 2>/dev/null || echo '?'), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
declare -A upm
for d in $levels; do
  out=$(bash tests/integration/netns_hosts.sh --port "$port" --drop "$d" "${where[@]+"${where[@]}"}" --measure "$updates" 2>&1) || {
    echo "$out" | tail -20
    echo "e2e_loss: the run at $d% failed" >&2
    exit 1
  }
  line=$(echo "$out" | grep '^MEASURE: ' | tail -1)
  [ -n "$line" ] || { echo "$out" | tail -5; exit 1; }
  echo "$line"
  upm[$d]=$(echo "$line" | sed -n 's/.*updates_per_minute \([0-9.]*\)$/\1/p')
done
base=${upm[0]:-}
[ -n "$base" ] || exit 0
for d in $levels; do
  [ "$d" = 0 ] && continue
  awk -v d="$d" -v x="${upm[$d]}" -v b="$base" 'BEGIN { printf "retained at %s%% %.2f\n", d, x / b }'
done
