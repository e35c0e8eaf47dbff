#!/usr/bin/env bash
# The paper's offline table: every algorithm x method x dataset family x seed trained with
# masa_offline on the family's log, each trained policy evaluated with masa_eval (policy mean), then
# the table of mean and standard deviation over seeds next to each dataset's own mean return.
#   experiments/offline_table.sh --task a1_beam --datasets runs/datasets/a1_beam \
#       --env-of runs/a1_stages/policy.bin [--algos "bc iql"] [--methods "sa sasa-data masa"] \
#       [--families "expert half_expert weak_expert mixed"] [--seeds "0 1 2 3 4"] [--steps N] \
#       [--bc-steps N] [--iql-steps N] [--episodes 100] [--eval-seed 1000000] [--jobs N] [--threads T] \
#       [--out DIR] [--set key=value ...]
#   experiments/offline_table.sh --out DIR               (go on with DIR's table after a kill)
#   experiments/offline_table.sh --summarize --out DIR   (only table.md and table.csv, of the runs done so far)
# Resumable: a run with its `done` file is not redone; a run whose training finished (`trained`)
# is only evaluated again; any other run starts afresh (masa_offline has no checkpoint). Runs are
# taken seed by seed, so a table stopped early has whole seeds of every cell.
# Results: DIR/<family>/<algo>_<method>_s<seed>/ (masa_offline's run directory, with eval.txt and
# eval.csv of masa_eval and result.csv, its numbers), its log beside it (the exact commands),
# DIR/table.txt (the table's definition), DIR/runs.csv, DIR/table.csv and DIR/table.md.
# Datasets: DATASETS/<family>.lcmlog; a family's own mean return is read from DATASETS/families.csv
# (masa_dataset families) or else from `masa_dataset info`.
# MASA_BUILD_DIR chooses the binaries (default build; relative paths are the checkout's).
set -euo pipefail
caller=$(pwd)
cd "$(dirname "$0")/.."
source experiments/job_queue.sh
repo=$(pwd)
abs() { case "$1" in /*) echo "$1" ;; *) echo "$caller/$1" ;; esac; }
die() { echo "offline_table.sh: $*" >&2; exit 2; }

task="" datasets="" algos="" methods="" families="" seeds="" steps="" bc_steps="" iql_steps="" episodes=""
eval_seed="" env_of="" jobs="" threads=1 out="" sets=() summarize=0
while [ $# -gt 0 ]; do
  case "$1" in
    --task) task=$2; shift 2 ;;
    --datasets) datasets=$(abs "$2"); shift 2 ;;
    --algos) algos=$2; shift 2 ;;
    --methods) methods=$2; shift 2 ;;
    --families) families=$2; shift 2 ;;
    --seeds) seeds=$2; shift 2 ;;
    --steps) steps=$2; shift 2 ;;
    --bc-steps) bc_steps=$2; shift 2 ;;
    --iql-steps) iql_steps=$2; shift 2 ;;
    --episodes) episodes=$2; shift 2 ;;
    --eval-seed) eval_seed=$2; shift 2 ;;
    --env-of) env_of=$(abs "$2"); shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --out) out=$(abs "$2"); shift 2 ;;
    --set) sets+=("$2"); shift 2 ;;
    --summarize) summarize=1; shift ;;
    -h|--help) sed -n '2,21p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) die "unknown option '$1' (see --help)" ;;
  esac
done
[ $# -eq 0 ] || die "unexpected argument '$1'"
for v in steps bc_steps iql_steps episodes eval_seed jobs threads; do
  [ -z "${!v}" ] || [[ "${!v}" =~ ^[0-9]+$ ]] || die "--${v//_/-} wants a whole number, not '${!v}'"
done
build=${MASA_BUILD_DIR:-build}
case "$build" in /*) ;; *) build="$repo/$build" ;; esac
for t in masa_offline masa_eval masa_dataset; do
  [ -x "$build/tools/$t" ] || die "$build/tools/$t is missing: run scripts/build.sh (or set MASA_BUILD_DIR)"
done

# The table's definition is kept in DIR/table.txt: the same command, or --out DIR alone, goes on
# with it; a different definition for the same DIR is refused.
keys=(task datasets algos methods families seeds bc_steps iql_steps episodes eval_seed env_of)
if [ -n "$out" ] && [ -f "$out/table.txt" ]; then
  saved=$(cat "$out/table.txt")
  [ -n "$steps" ] && { bc_steps=${bc_steps:-$steps}; iql_steps=${iql_steps:-$steps}; }
  for k in "${keys[@]}"; do
    want=${!k}; have=$(sed -n "s/^$k=//p" <<< "$saved")
    if [ -n "$want" ] && [ "$want" != "$have" ]; then
      die "$out is the table $k='$have', not '$want' (use another --out)"
    fi
    printf -v "$k" '%s' "$have"
  done
  g_sets=$(sed -n 's/^set=//p' <<< "$saved")
  if [ ${#sets[@]} -gt 0 ] && [ "$(printf '%s\n' "${sets[@]}")" != "$g_sets" ]; then
    die "$out was made with other --set options:"$'\n'"$g_sets"
  fi
  mapfile -t sets < <(printf '%s' "$g_sets" | sed '/^$/d')
elif [ "$summarize" = 1 ]; then
  die "--summarize needs --out with an existing table (its table.txt)"
else
  task=${task:-a1_beam}
  datasets=${datasets:-$repo/runs/datasets/$task}
  algos=${algos:-bc iql} methods=${methods:-sa sasa-data masa}
  families=${families:-expert half_expert weak_expert mixed} seeds=${seeds:-0 1 2 3 4}
  bc_steps=${bc_steps:-${steps:-5000}} iql_steps=${iql_steps:-${steps:-10000}}
  episodes=${episodes:-100} eval_seed=${eval_seed:-1000000}
  for a in $algos; do case "$a" in bc|iql) ;; *) die "unknown algorithm '$a' (bc, iql)" ;; esac; done
  for m in $methods; do case "$m" in sa|sasa-data|masa) ;; *) die "unknown method '$m' (sa, sasa-data, masa)" ;; esac; done
  for f in $families; do [ -f "$datasets/$f.lcmlog" ] || die "no dataset $datasets/$f.lcmlog (family '$f')"; done
  [ -z "$env_of" ] || [ -e "$env_of" ] || die "--env-of $env_of does not exist"
  out=${out:-$repo/runs/offline_table_${task}_$(date +%Y%m%d_%H%M%S)}
  mkdir -p "$out"
  { for k in "${keys[@]}"; do echo "$k=${!k}"; done
    for x in "${sets[@]+"${sets[@]}"}"; do echo "set=$x"; done
    echo "# started $(date -u +%FT%TZ) at commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown), binaries $build"
  } > "$out/table.txt"
fi
out=$(cd "$out" && pwd)
# One table per directory (a second would start the same runs afresh over the first's); --summarize
# only reads finished runs, so it may look at a table while it runs.
if [ "$summarize" = 0 ]; then
  exec {table_lock}> "$out/.table.lock"
  flock -n "$table_lock" || { echo "offline_table.sh: another table is running in $out (wait for it, or stop it first)" >&2; exit 3; }
fi

# One run: train (unless trained), evaluate, write result.csv (the means over the episodes of the
# return, the success rate, and every progress figure of eval.csv), then `done`.
run_one() {
  local f=$1 a=$2 m=$3 s=$4 dir="$out/$1/$2_$3_s$4" rc=0 cmd target reached t0 t1 t2
  local log="$dir.log" steps_var="${2}_steps"
  local n=${!steps_var}
  t0=$(date +%s.%N)
  if [ ! -f "$dir/trained" ]; then
    rm -rf "$dir"
    local args=(--dataset "$datasets/$f.lcmlog" --algo "$a" --method "$m" --steps "$n" --seed "$s" --out "$dir"
                --threads "$threads" --quiet --set offline.eval_every=0 --set offline.final_eval_episodes=0)
    [ -n "$env_of" ] && args+=(--env-of "$env_of")
    while IFS= read -r x; do [ -n "$x" ] && args+=(--set "$x"); done <<< "$MASA_TABLE_SETS"
    cmd="cd $(printf '%q' "$repo") && OMP_NUM_THREADS=$threads $(printf '%q ' "$build/tools/masa_offline" "${args[@]}")"
    echo "# $(date -u +%FT%TZ): $cmd" >> "$log"
    bash -c "$cmd" >> "$log" 2>&1 || rc=$?
    # Trained when it exited 0 and its last metrics row is the last step.
    reached=$(tail -n 1 "$dir/metrics.csv" 2>/dev/null | cut -d, -f1)
    if [ "$rc" != 0 ] || [ "$reached" != "$n" ] || [ ! -f "$dir/policy.bin" ]; then
      echo "offline_table.sh: FAILED training $f $a $m seed $s (exit $rc, step ${reached:-none} of $n, see $log)"
      return 0
    fi
    echo "# trained $n steps in $(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }') s" >> "$log"
    touch "$dir/trained"
  fi
  t1=$(date +%s.%N)
  cmd="cd $(printf '%q' "$repo") && OMP_NUM_THREADS=$threads $(printf '%q ' "$build/tools/masa_eval" "$dir" \
       --episodes "$episodes" --seed "$eval_seed" --threads "$threads" --csv "$dir/eval.csv")"
  echo "# $(date -u +%FT%TZ): $cmd > $dir/eval.txt" >> "$log"
  rm -f "$dir/eval.csv"
  bash -c "$cmd" > "$dir/eval.txt" 2>> "$log" || rc=$?
  t2=$(date +%s.%N)
  local rows; rows=$(($(wc -l < "$dir/eval.csv" 2>/dev/null || echo 1) - 1))
  if [ "$rc" != 0 ] || [ "$rows" != "$episodes" ]; then
    echo "offline_table.sh: FAILED evaluating $f $a $m seed $s (exit $rc, $rows of $episodes episodes, see $log)"
    return 0
  fi
  echo "# evaluated $episodes episodes in $(awk -v a="$t1" -v b="$t2" 'BEGIN { printf "%.1f", b - a }') s" >> "$log"
  # result.csv: the run's keys, the means over its episodes, training and evaluation seconds.
  awk -F, -v pre="$task,$a,$m,$f,$s,$n,$episodes" -v tr="$(sed -n 's/^# trained [0-9]* steps in \([0-9.]*\) s$/\1/p' "$log" | tail -1)" \
      -v ev="$(awk -v a="$t1" -v b="$t2" 'BEGIN { printf "%.1f", b - a }')" '
    NR == 1 { for (i = 1; i <= NF; ++i) {
                if ($i == "return" || $i == "success") { col[++k] = i; name[k] = $i }
                else if (i > 1 && seen_success && $i !~ /^term_/ && !stop) { col[++k] = i; name[k] = $i }
                if ($i == "success") seen_success = 1
                if ($i ~ /^term_/) stop = 1 }
              next }
    { for (j = 1; j <= k; ++j) sum[j] += $col[j]; ++rows }
    END { h = "task,algo,method,family,seed,steps,episodes"; r = pre
          for (j = 1; j <= k; ++j) { h = h "," name[j]; v = sum[j] / rows
                                     r = r "," ((name[j] == "success" && v < 0) ? "nan" : sprintf("%.6g", v)) }
          print h ",train_s,eval_s"; print r "," (tr == "" ? "nan" : tr) "," ev }' "$dir/eval.csv" > "$dir/result.csv"
  touch "$dir/done"
  echo "offline_table.sh: done $f $a $m seed $s: $(sed -n 2p "$dir/result.csv")"
}

# The dataset's own numbers: families.csv of masa_dataset families, or masa_dataset info.
dataset_stats() {
  local f=$1 line
  if [ -f "$datasets/families.csv" ]; then
    line=$(awk -F, -v f="$f" 'NR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; next }
      $c["family"] == f { print $c["episodes"] "," $c["return_mean"] "," $c["return_std"] "," ($c["success_rate"] < 0 ? "nan" : $c["success_rate"]) }' \
      "$datasets/families.csv")
    [ -n "$line" ] && { echo "$line"; return; }
  fi
  "$build/tools/masa_dataset" info "$datasets/$f.lcmlog" 2>/dev/null | awk '
    /^task / { for (i = 1; i <= NF; ++i) { if ($i == "episodes,") e = $(i-1); if ($i == "return") { r = $(i+1); sd = $(i+3) }
                                            if ($i == "success") s = $(i+1) }
               sub(/,$/, "", e); sub(/,$/, "", sd); print e "," r "," sd "," (s == "" ? "nan" : s); exit }'
}

# table.csv and table.md from every finished run's result.csv.
summarize() {
  local files=() f
  for f in "$out"/*/*_s*/result.csv; do [ -f "$f" ] && [ -f "$(dirname "$f")/done" ] && files+=("$f"); done
  if [ ${#files[@]} -eq 0 ]; then echo "offline_table.sh: no finished run in $out yet: no table" >&2; return 0; fi
  { sed -n 1p "${files[0]}"; for f in "${files[@]}"; do sed -n 2p "$f"; done; } > "$out/runs.csv"
  : > "$out/.datasets.csv"
  for f in $families; do echo "$f,$(dataset_stats "$f")" >> "$out/.datasets.csv"; done
  awk -F, -v algos="$algos" -v methods="$methods" -v families="$families" -v nseeds="$(wc -w <<< "$seeds")" \
      -v task="$task" -v bc_steps="$bc_steps" -v iql_steps="$iql_steps" -v episodes="$episodes" \
      -v csv="$out/table.csv" -v md="$out/table.md" -v when="$(date -u +%FT%TZ)" '
    FNR == NR { ds_n[$1] = $2; ds_r[$1] = $3; ds_sd[$1] = $4; ds_s[$1] = $5; next }
    FNR == 1 { for (i = 1; i <= NF; ++i) if ($i == "episodes") first = i + 1
               for (i = first; i <= NF && $i != "train_s"; ++i) { metric[++nm] = $i; mcol[nm] = i }
               next }
    { key = $2 SUBSEP $3 SUBSEP $4; ++n[key]
      for (j = 1; j <= nm; ++j) { v = $mcol[j]; if (v == "nan") { nan[key, j] = 1; continue } x[key, j, n[key]] = v } }
    function stat(key, j,   i, m, s) {   # sets M and SD over the seeds; SD of one seed is nan
      if (n[key] == 0 || nan[key, j]) { M = "nan"; SD = "nan"; return }
      m = 0; for (i = 1; i <= n[key]; ++i) m += x[key, j, i]; m /= n[key]
      s = 0; for (i = 1; i <= n[key]; ++i) s += (x[key, j, i] - m) ^ 2
      M = m; SD = n[key] > 1 ? sqrt(s / (n[key] - 1)) : "nan" }
    function cell(key, j, digits) {
      stat(key, j); if (M == "nan") return n[key] == 0 ? "" : "n/a"
      return sprintf("%." digits "f", M) (SD == "nan" ? "" : sprintf(" ± %." digits "f", SD)) (n[key] < nseeds ? " (" n[key] (n[key] == 1 ? " seed)" : " seeds)") : "") }
    END {
      na = split(algos, A, " "); nme = split(methods, ME, " "); nf = split(families, F, " ")
      h = "task,algo,method,family,seeds"
      for (j = 1; j <= nm; ++j) h = h "," metric[j] "_mean," metric[j] "_std"
      print h ",dataset_episodes,dataset_return_mean,dataset_return_std,dataset_success" > csv
      for (a = 1; a <= na; ++a) for (m = 1; m <= nme; ++m) for (f = 1; f <= nf; ++f) {
        key = A[a] SUBSEP ME[m] SUBSEP F[f]; r = task "," A[a] "," ME[m] "," F[f] "," n[key] + 0
        for (j = 1; j <= nm; ++j) { stat(key, j); r = r "," (M == "nan" ? "nan" : sprintf("%.6g", M)) "," (SD == "nan" ? "nan" : sprintf("%.6g", SD)) }
        print r "," ds_n[F[f]] "," ds_r[F[f]] "," ds_sd[F[f]] "," ds_s[F[f]] > csv }
      print "# Offline table: " task > md
      print "" > md
      budget = ""
      for (a = 1; a <= na; ++a) budget = budget (a > 1 ? ", " : "") toupper(A[a]) " " (A[a] == "bc" ? bc_steps : iql_steps) " steps"
      print budget "; each policy evaluated with masa_eval, policy mean, " episodes " episodes. Mean ± standard" \
            " deviation (n - 1) over training seeds, " nseeds " per cell unless said. Written " when "." > md
      for (j = 1; j <= nm; ++j) {
        if (metric[j] == "success") { any = 0; for (k in n) { stat(k, j); if (M != "nan") any = 1 } if (!any) continue }
        print "" > md; print "## " metric[j] " (policy mean)" > md; print "" > md
        ds_col = (metric[j] == "return")
        h = "| family |" (ds_col ? " dataset return |" : ""); sep = "|---|" (ds_col ? "---:|" : "")
        for (a = 1; a <= na; ++a) for (m = 1; m <= nme; ++m) { h = h " " toupper(A[a]) " " ME[m] " |"; sep = sep "---:|" }
        print h > md; print sep > md
        digits = (metric[j] == "return") ? 1 : 3
        for (f = 1; f <= nf; ++f) {
          r = "| " F[f] " |" (!ds_col ? "" : " " (ds_r[F[f]] == "" ? "?" : sprintf("%.1f ± %.1f", ds_r[F[f]], ds_sd[F[f]])) " |")
          for (a = 1; a <= na; ++a) for (m = 1; m <= nme; ++m) r = r " " cell(A[a] SUBSEP ME[m] SUBSEP F[f], j, digits) " |"
          print r > md } }
    }' "$out/.datasets.csv" "$out/runs.csv"
  rm -f "$out/.datasets.csv"
  echo "offline_table.sh: ${#files[@]} finished runs: $out/table.md, $out/table.csv"
}

if [ "$summarize" = 0 ]; then
  queue="$out/.queue" qlock="$out/.queue.lock"
  : > "$queue"
  total=0 finished=0
  for s in $seeds; do for f in $families; do for a in $algos; do for m in $methods; do
    total=$((total + 1))
    if [ -f "$out/$f/${a}_${m}_s$s/done" ]; then finished=$((finished + 1)); else echo "$f $a $m $s" >> "$queue"; fi
  done; done; done; done
  jobs=${jobs:-$(( $(nproc) / threads > 0 ? $(nproc) / threads : 1 ))}
  echo "offline_table.sh: $total runs ($algos / $methods / $families / seeds $seeds), $finished already done," \
       "$jobs at a time, into $out"
  export build repo out task datasets bc_steps iql_steps episodes eval_seed env_of threads queue qlock
  export MASA_TABLE_SETS; MASA_TABLE_SETS=$(printf '%s\n' "${sets[@]+"${sets[@]}"}")
  worker() {
    local line
    while :; do
      line=$(pop_job "$queue" "$qlock")
      [ -n "$line" ] || return 0
      # shellcheck disable=SC2086
      run_one $line
    done
  }
  export -f run_one worker pop_job
  for f in $families; do mkdir -p "$out/$f"; done
  pids=()
  # On a kill: the workers and their runs end; the table exits after them, so that a rerun never
  # meets a run still writing. An unfinished run has no `done` and is redone (or only evaluated).
  stop_all() { stop_workers "offline_table.sh: stopped; run the same command again (or offline_table.sh --out $out) to go on" "${pids[@]}"; }
  trap stop_all INT TERM
  for ((i = 0; i < jobs; ++i)); do bash -c worker & pids+=($!); done
  wait "${pids[@]}"
  rm -f "$queue" "$qlock"
fi
summarize
