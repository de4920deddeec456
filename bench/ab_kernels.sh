#!/bin/bash
# Kernel against kernel: two builds of a benchmark binary (e.g. main's
# bench_sphere_side_by_side and a branch's) run alternately, pinned to one
# core, on each SIMD path; prints the CPU seconds of every round per path
# and binary (the figure performance.md's "kernel against kernel" tables
# give; compare medians, or the ratios round by round).
#
#   bench/ab_kernels.sh ROUNDS "ARGS" BIN_A BIN_B
#   e.g. bench/ab_kernels.sh 3 "--cells 10 --steps 1000 --preload 100" \
#          /tmp/base/bench_sphere_side_by_side build/bench_sphere_side_by_side
#
# Environment: PATHS (default "avx512 avx2"; DEMCAL_SIMD values), CORE
# (default 0). Note the load (uptime) beside the figures: the two vCPUs of
# the test machines share a core.
set -euo pipefail
if [ $# -ne 4 ]; then
  sed -n '2,15p' "$0" >&2
  exit 2
fi
rounds=$1 args=$2 a=$3 b=$4
paths=${PATHS:-"avx512 avx2"} core=${CORE:-0}
for bin in "$a" "$b"; do
  [ -x "$bin" ] || { echo "ab_kernels.sh: $bin: not an executable" >&2; exit 2; }
done
for _ in $(seq "$rounds"); do
  for p in $paths; do
    for bin in "$a" "$b"; do
      # shellcheck disable=SC2086  # ARGS is a list of options
      t=$(DEMCAL_SIMD=$p taskset -c "$core" "$bin" $args | grep -o 'cpu_seconds=[0-9.e+-]*' | cut -d= -f2)
      echo "$p $bin $t"
    done
  done
done | awk '{k = $1 " " $2; v[k] = v[k] " " $3} END {for (k in v) print k ":" v[k]}' | sort
