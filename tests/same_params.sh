#!/usr/bin/env bash
# Behaviour check for refactoring: calibrates the shipped scenes with two
# builds of demcal and compares their params.json byte for byte (run both on
# the same machine: the SIMD path is part of the result; set DEMCAL_SIMD to
# pin it).
#   tests/same_params.sh BEFORE_BUILD_DIR AFTER_BUILD_DIR [scene ...]
set -euo pipefail
before=$1 after=$2
shift 2
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(hex_5x5 hex_10x10 hex_20x20 random_400)
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
status=0
for scene in "${scenes[@]}"; do
  for side in before after; do
    build=${!side}
    # Exit 1 (no certified answer) is a result too: compare it all the same.
    "$build/demcal" calibrate "$root/configs/$scene.json" -o "$work/$side-$scene" -q > /dev/null ||
      [ $? -eq 1 ]
  done
  if cmp -s "$work/before-$scene/params.json" "$work/after-$scene/params.json"; then
    echo "same      $scene"
  else
    echo "DIFFERENT $scene"
    diff "$work/before-$scene/params.json" "$work/after-$scene/params.json" | head -20
    status=1
  fi
done
exit $status
