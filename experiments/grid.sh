#!/usr/bin/env bash
# An experiment grid: every task x method x seed trained with masa_train (learner and one actor in
# one process, deterministic per seed), as many runs at once as there are cores, then one
# comparison plot per task (mean return over seeds against env steps, one line per method).
#   experiments/grid.sh --tasks "a1_beam ant_acrobatic" --methods "masa sa sasa ma" --seeds "0 1 2" \
#       --updates 300 [--jobs N] [--out DIR] [--set key=value ...]
#   experiments/grid.sh --replot --out DIR --tasks ... --methods ... --seeds ...   (summary and plots only)
# Results: DIR/<task>/<method>_s<seed>/ (the run directories: config.yaml, metrics.csv, ...),
# DIR/<task>/summary.csv (final return per run: mean of the last 10 updates) and
# DIR/<task>/compare.png. MASA_BUILD_DIR chooses the build (default build).
set -euo pipefail
cd "$(dirname "$0")/.."

tasks="a1_beam" methods="masa sa" seeds="0" updates=200 jobs=$(nproc) out="" sets=() replot=0
while [ $# -gt 0 ]; do
  case "$1" in
    --tasks) tasks=$2; shift 2 ;;
    --methods) methods=$2; shift 2 ;;
    --seeds) seeds=$2; shift 2 ;;
    --updates) updates=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --set) sets+=(--set "$2"); shift 2 ;;
    --replot) replot=1; shift ;;
    *) echo "grid.sh: unknown option '$1'" >&2; exit 2 ;;
  esac
done
build=${MASA_BUILD_DIR:-build}
train="$build/tools/masa_train"
if [ "$replot" = 1 ]; then
  [ -n "$out" ] && [ -d "$out" ] || { echo "grid.sh: --replot needs --out with an existing grid" >&2; exit 2; }
else
  [ -x "$train" ] || { echo "grid.sh: $train is missing: run deploy/build.sh first" >&2; exit 2; }
  out=${out:-experiments/results/grid_$(date +%Y%m%d_%H%M%S)}
  mkdir -p "$out"

  # One line per run; xargs runs them `jobs` at a time, each on one thread.
  runs="$out/runs.txt"
  : > "$runs"
  for t in $tasks; do for m in $methods; do for s in $seeds; do echo "$t $m $s" >> "$runs"; done; done; done
  total=$(wc -l < "$runs")
  echo "grid.sh: $total runs ($tasks / $methods / seeds $seeds), $updates updates each, $jobs at a time, into $out"
  printf '%s\n' "${sets[@]+"${sets[@]}"}" > "$out/sets.txt"

  export train updates out
  run_one() {
    local t=$1 m=$2 s=$3 dir="$out/$1/$2_s$3"
    mapfile -t extra < "$out/sets.txt"
    local args=()
    for x in "${extra[@]}"; do [ -n "$x" ] && args+=("$x"); done
    if OMP_NUM_THREADS=1 "$train" --quiet --updates "$updates" --run-dir "$dir" \
         --set task="$t" --set method="$m" --set seed="$s" "${args[@]}" > "$dir.log" 2>&1; then
      echo "grid.sh: done $t $m seed $s"
    else
      echo "grid.sh: FAILED $t $m seed $s (see $dir.log)"
    fi
  }
  export -f run_one
  mkdir -p $(for t in $tasks; do echo "$out/$t"; done)
  xargs -P "$jobs" -L 1 bash -c 'run_one "$@"' _ < "$runs"
fi

for t in $tasks; do
  summary="$out/$t/summary.csv"
  echo "method,seed,env_steps,final_return" > "$summary"
  for m in $methods; do for s in $seeds; do
    csv="$out/$t/${m}_s$s/metrics.csv"
    [ -f "$csv" ] || continue
    awk -F, -v m="$m" -v s="$s" 'NR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; next }
      { steps = $c["env_steps"]; r[NR] = $c["return"] }
      END { n = 0; sum = 0; for (i = NR; i > 1 && n < 10; --i) if (r[i] != "nan") { sum += r[i]; ++n }
            printf "%s,%s,%s,%s\n", m, s, steps, n ? sum / n : "nan" }' "$csv" >> "$summary"
  done; done
  # Per method: the mean over seeds of each update's return (smoothed over 5 updates) for the plot.
  for m in $methods; do
    files=$(for s in $seeds; do f="$out/$t/${m}_s$s/metrics.csv"; [ -f "$f" ] && echo "$f"; done)
    [ -n "$files" ] || continue
    awk -F, 'FNR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; next }
      $c["return"] != "nan" { k = FNR; steps[k] = $c["env_steps"]; sum[k] += $c["return"]; n[k]++; if (k > K) K = k }
      END { for (k = 2; k <= K; ++k) if (n[k]) { w[k] = sum[k] / n[k] }
            for (k = 2; k <= K; ++k) if (k in w) { s = 0; c2 = 0; for (j = k - 4; j <= k; ++j) if (j in w) { s += w[j]; ++c2 }
                                                   printf "%s %g\n", steps[k], s / c2 } }' $files > "$out/$t/$m.dat"
  done
  plot=""
  for m in $methods; do [ -s "$out/$t/$m.dat" ] && plot+="${plot:+, }\"$m.dat\" using 1:2 with lines lw 2 title \"$m\""; done
  if command -v gnuplot > /dev/null && [ -n "$plot" ]; then
    (cd "$out/$t" && gnuplot -e "set terminal pngcairo size 900,600; set output 'compare.png'; set termoption noenhanced;
      set title '$t: mean episode return (mean over seeds $seeds, smoothed over 5 updates)'; set grid;
      set xlabel 'env steps'; set ylabel 'return'; set key bottom right; plot $plot")
  fi
  echo "grid.sh: $t:"; column -s, -t "$summary"
done
echo "grid.sh: results in $out"
