#!/usr/bin/env bash
# One line naming this machine for a record: host, cores, CPU model, and what decides whether a
# run is bit for bit another's: the CPU generation and its widest vector ISA. Builds are
# -march=native (MASA_NATIVE), so the same commit built on an AVX-512 machine and on an AVX2 one
# rounds differently: the same seed agrees for a few updates and then drifts apart.
#   experiments/machine.sh    ->  vm, 2 cores, AMD EPYC (x86 family 25 model 1; avx2, no avx512)
set -euo pipefail
field() { grep -m1 "^$1[[:space:]]*:" /proc/cpuinfo 2> /dev/null | cut -d: -f2 | sed 's/^ *//'; }
flags=" $(field flags) "
isa="no avx"
case "$flags" in *" avx2 "*) isa="avx2" ;; *" avx "*) isa="avx" ;; esac
case "$flags" in *" avx512f "*) isa="$isa, avx512" ;; *) [ "$isa" = "no avx" ] || isa="$isa, no avx512" ;; esac
model=$(field "model name") family=$(field "cpu family") gen=""
[ -z "$family" ] || gen="x86 family $family model $(field model); "
echo "$(hostname), $(nproc --all) cores, ${model:-unknown CPU} ($gen$isa)"
