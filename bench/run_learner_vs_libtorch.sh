#!/usr/bin/env bash
# Issue #4: our learner minibatch step (bench_learner_step) against the same step in LibTorch
# (bench_learner_step_libtorch), run in one session with the set-ups interleaved in a random order
# each round; prints the medians as a markdown table.
#
# Usage: bench/run_learner_vs_libtorch.sh [rounds]        (default 5 rounds)
# Environment: MASA_BUILD_DIR (default ./build), MASA_BENCH_BATCH (default 32768),
#   MASA_BENCH_NETS (default "Policy ActorCritic"), MASA_BENCH_MIN_TIME (seconds a run lasts, 1),
#   MASA_BENCH_SETUPS (default: all four below), MASA_BENCH_KEEP (a folder to keep the JSON in).
#
# Set-ups (LibTorch is Debian's libtorch-dev, 1.13.1; scripts/install_bench_deps.sh installs it):
#   ours            bench_learner_step, 1 and 2 OpenMP threads
#   torch-refblas   LibTorch as libtorch-dev alone installs it: the reference BLAS (libblas3)
#   torch-openblas  LibTorch on OpenBLAS (the libblas.so.3 alternative once libopenblas0 is
#                   installed), OpenBLAS choosing its kernel itself, default heap and threads
#   torch-tuned     as ../shared/PERFORMANCE.md: OpenBLAS with the SkylakeX kernel, a heap that
#                   keeps freed memory (MALLOC_MMAP_MAX_=0, MALLOC_TRIM_THRESHOLD_ large) and
#                   torch::set_num_threads(2)
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
build=${MASA_BUILD_DIR:-$root/build}
rounds=${1:-5}
nets=${MASA_BENCH_NETS:-Policy ActorCritic}
min_time=${MASA_BENCH_MIN_TIME:-1}
ours=$build/bench/bench_learner_step
torch=$build/bench/libtorch/bench_learner_step_libtorch
libdir=/usr/lib/x86_64-linux-gnu

bash "$root/bench/build_benchmarks.sh" "$build"
[ -x "$torch" ] || {
  echo "missing $torch: run scripts/install_bench_deps.sh, then reconfigure and build" >&2
  exit 1
}
read -r -a setups <<<"${MASA_BENCH_SETUPS:-ours torch-refblas torch-openblas torch-tuned}"
if [[ " ${setups[*]} " == *" torch-refblas "* && ! -e "$libdir/blas/libblas.so.3" ]]; then
  echo "note: no reference BLAS in $libdir/blas; torch-refblas skipped" >&2
  read -r -a setups <<<"${setups[*]/torch-refblas/}"
fi

filter="^BM_[A-Za-z]*LearnerStep/($(echo "$nets" | tr ' ' '|'))/"
if [ -n "${MASA_BENCH_KEEP:-}" ]; then
  out=$MASA_BENCH_KEEP
  mkdir -p "$out"
else
  out=$(mktemp -d)
  trap 'rm -rf "$out"' EXIT
fi

run() {  # set-up, round
  local file="$out/$1.$2.json"
  local common=(--benchmark_filter="$filter" --benchmark_out="$file" --benchmark_out_format=json)
  case $1 in
    ours) "$ours" "${common[@]}" --benchmark_min_time="$min_time" ;;
    # One step takes seconds on the reference BLAS: one timed step is enough.
    torch-refblas) LD_LIBRARY_PATH="$libdir/blas" "$torch" "${common[@]}" --benchmark_min_time=0.01 ;;
    torch-openblas) LD_LIBRARY_PATH="$libdir/openblas-pthread" "$torch" "${common[@]}" --benchmark_min_time="$min_time" ;;
    torch-tuned)
      LD_LIBRARY_PATH="$libdir/openblas-pthread" OPENBLAS_CORETYPE=SkylakeX MALLOC_MMAP_MAX_=0 \
        MALLOC_TRIM_THRESHOLD_=4294967296 MASA_TORCH_THREADS=2 \
        "$torch" "${common[@]}" --benchmark_min_time="$min_time"
      ;;
  esac >/dev/null 2>"$out/$1.$2.log" || { cat "$out/$1.$2.log" >&2; exit 1; }
}

echo "load before: $(uptime)"
for r in $(seq "$rounds"); do
  for s in $(printf '%s\n' "${setups[@]}" | shuf); do
    echo "round $r/$rounds: $s ($(cut -d' ' -f1-3 /proc/loadavg))" >&2
    run "$s" "$r"
  done
done
echo "load after:  $(uptime)"

python3 - "$out" <<'EOF'
import glob, json, os, re, statistics, sys

rows = {}  # (net, set-up label) -> list of (ms, gflops, of_peak)
for path in sorted(glob.glob(os.path.join(sys.argv[1], "*.json"))):
    setup = os.path.basename(path).split(".")[0]
    for b in json.load(open(path))["benchmarks"]:
        m = re.match(r"BM_\w*LearnerStep/(\w+)/batch:(\d+)(?:/threads:(\d+))?", b["name"])
        net, batch, threads = m.group(1), m.group(2), m.group(3)
        label = f"{setup}, {threads} thread{'s' if threads != '1' else ''}" if threads else setup
        rows.setdefault((net, batch, label), []).append((b["real_time"], b["GFLOPs"], b["of_peak"]))

order = ["ours, 1 thread", "ours, 2 threads", "torch-refblas", "torch-openblas", "torch-tuned"]
for net, batch in sorted({(k[0], k[1]) for k in rows}, key=lambda k: k[0] != "Policy"):
    med = {k[2]: statistics.median(v[0] for v in rows[k]) for k in rows if k[:2] == (net, batch)}
    best = med.get("ours, 2 threads")
    print(f"\n{net}, batch {batch} (medians of {max(len(v) for v in rows.values())} rounds)\n")
    print("| set-up | ms per step (min-max) | GFLOP/s | of peak | ours (2 threads) faster by |")
    print("|---|---|---|---|---|")
    for label in order:
        key = (net, batch, label)
        if key not in rows:
            continue
        v = rows[key]
        ms = [x[0] for x in v]
        ratio = f"{med[label] / best:.2f}x" if best else "-"
        print(f"| {label} | {statistics.median(ms):.1f} ({min(ms):.1f}-{max(ms):.1f}) | "
              f"{statistics.median(x[1] for x in v):.0f} | {statistics.median(x[2] for x in v):.2f} | {ratio} |")
EOF
