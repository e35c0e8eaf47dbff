#!/usr/bin/env bash
# The unit tests under AddressSanitizer and UndefinedBehaviorSanitizer (issue #9): a build of its
# own (build-sanitize/, -DMASA_SANITIZE=ON, no benchmarks), then every GoogleTest case of
# masa_unit_tests (CTest label "unit"); a sanitizer report fails the test that caused it.
# Not part of scripts/test.sh: the instrumented build and run take about twice the plain suite's time.
#   scripts/test_sanitizers.sh [ctest args...]      e.g. -R Wire
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${MASA_SANITIZE_BUILD_DIR:-build-sanitize}
cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMASA_SANITIZE=ON -DMASA_BUILD_BENCHMARKS=OFF > /dev/null
cmake --build "$dir" -j"$(nproc)" --target masa_unit_tests
# LeakSanitizer: MuJoCo's and LCM's process-lifetime allocations are not ours to free.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
ctest --test-dir "$dir" -L unit -j"$(nproc)" --output-on-failure "$@"
