#!/usr/bin/env bash
# Issue #14 on a machine that has none of masa's other dependencies (no MuJoCo, LCM or CMake
# packages; the device machine): builds only the networks (common/nn, Eigen, OpenMP) and their
# benchmarks with g++, then measures this CPU the way docs/benchmarks.md's per-CPU table does: the
# fp32 FMA peak and CPU model, the learner step (policy and actor-critic) at 32768, 4096 and 1024
# columns on 1 and 2 threads, the chunk-fused prototype, and single-sample to batch-16 inference.
#
#   bench/cpu_kernels.sh OUT_DIR [DEPS_DIR]
#
# DEPS_DIR holds what the machine lacks, made here by `bench/cpu_kernels.sh --collect DEPS_DIR`:
# Eigen's and Google Benchmark's headers and Benchmark's library. Without it the system's are used.
# Everything lands in OUT_DIR: cpu.txt (lscpu, the compiler), build.log, and one JSON and one text
# file per benchmark; the last lines printed are the medians. MASA_CPU_KERNELS_BATCHES chooses the
# batches (default "32768 4096 1024").
#
# On the device machine (one call; .bench_deps is git-ignored and carried; $OUT takes 8 files at
# most, so the results come back as one archive):
#   bench/cpu_kernels.sh --collect .bench_deps                                  # here, once
#   run: command "bash bench/cpu_kernels.sh /tmp/ck .bench_deps; tar -C /tmp/ck --exclude='bench_*'
#        -czf $OUT/cpu_kernels.tgz .", carry [".bench_deps"], timeout_s 540
# Here (2 vCPUs, grid running) the build took 69 s and a run of MASA_CPU_KERNELS_BATCHES=1024 3 min.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)

if [ "${1:-}" = "--collect" ]; then
  deps=${2:?--collect needs a folder}
  mkdir -p "$deps/include" "$deps/lib"
  cp -r /usr/include/eigen3/Eigen /usr/include/eigen3/unsupported "$deps/include/"
  cp -r /usr/include/benchmark "$deps/include/"
  cp -L /usr/lib/x86_64-linux-gnu/libbenchmark.so.1debian "$deps/lib/libbenchmark.so.1debian"
  ln -sf libbenchmark.so.1debian "$deps/lib/libbenchmark.so"
  cp /usr/lib/x86_64-linux-gnu/libbenchmark_main.a "$deps/lib/"
  echo "cpu_kernels.sh: $(du -sh "$deps" | cut -f1) in $deps"
  exit 0
fi

out=${1:?usage: bench/cpu_kernels.sh OUT_DIR [DEPS_DIR]}
deps=${2:-}
mkdir -p "$out"
out=$(cd "$out" && pwd)
inc=(-I"$root" -I"$root/bench") libs=()
if [ -n "$deps" ]; then
  deps=$(cd "$deps" && pwd)
  inc+=(-I"$deps/include")
  libs+=(-L"$deps/lib" -Wl,-rpath,"$deps/lib")
else
  inc+=(-I/usr/include/eigen3)
fi
cxx=${CXX:-g++}
{ lscpu; echo; "$cxx" --version | head -n 1; nproc --all; } > "$out/cpu.txt" 2>&1 || true

# The library once, then each benchmark against it; flags as the CMake Release build (-O3, native).
flags=(-std=c++20 -O3 -DNDEBUG -march=native -fopenmp -Wno-maybe-uninitialized)
obj="$out/obj"
mkdir -p "$obj"
start=$(date +%s)
{
  pids=()
  for src in "$root"/common/nn/*.cpp; do
    "$cxx" "${flags[@]}" "${inc[@]}" -c "$src" -o "$obj/$(basename "$src" .cpp).o" & pids+=($!)
  done
  for pid in "${pids[@]}"; do wait "$pid"; done
  pids=()
  for b in bench_learner_step bench_mlp bench_fused_step_prototype; do
    "$cxx" "${flags[@]}" "${inc[@]}" "$root/bench/$b.cpp" "$obj"/*.o "${libs[@]}" -lbenchmark_main -lbenchmark -lpthread \
      -o "$out/$b" & pids+=($!)
  done
  for pid in "${pids[@]}"; do wait "$pid"; done
} > "$out/build.log" 2>&1 || { echo "cpu_kernels.sh: build failed, see $out/build.log" >&2; tail -n 30 "$out/build.log" >&2; exit 1; }
echo "cpu_kernels.sh: built in $(( $(date +%s) - start )) s" | tee -a "$out/build.log"
rm -rf "$obj"

bench() {  # binary, file tag, MASA_BENCH_BATCH ("" for none), then benchmark options
  local b=$1 tag=$2 batch=$3
  shift 3
  env ${batch:+MASA_BENCH_BATCH=$batch} "$out/$b" "$@" --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
    --benchmark_out="$out/$tag.json" --benchmark_out_format=json > "$out/$tag.txt" 2>&1 || echo "cpu_kernels.sh: $tag failed" >&2
  grep -E "_median|^[a-z_0-9]+: " "$out/$tag.txt" | sed "s/^/$tag | /" || true
}
for batch in ${MASA_CPU_KERNELS_BATCHES:-32768 4096 1024}; do
  bench bench_learner_step "learner_step_$batch" "$batch"
  bench bench_fused_step_prototype "fused_prototype_$batch" "$batch"
done
bench bench_mlp inference "" --benchmark_filter='Infer|NarrowForward'
