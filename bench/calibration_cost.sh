#!/usr/bin/env bash
# What a calibration costs, against one final run at the parameters it
# finds (issue: "a few final runs' worth").
#
#   bench/calibration_cost.sh BUILD_DIR [OUT_DIR] [scene ...]
#
# For each scene: calibrates it (--jobs 2), then runs the calibrated
# parameters at 8x Nstep and compares the peaks. Prints one markdown table
# row per scene:
#   trials; particle-steps of the calibration / particle-steps of one final
#   run (machine-independent); consolidation steps; wall time and SIMD path
#   (machine-dependent); the calibrated peak against the 8x run.
# Not a test: wall times depend on the machine and its load (printed).
# The consolidation cache is a fresh folder in OUT_DIR: each calibration
# consolidates afresh (its wall time includes it), the 8x run reads it back.
set -euo pipefail
build=$1
out=${2:-$(mktemp -d)}
shift $(($# < 2 ? $# : 2))
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] ||
  scenes=(hex_5x5 hex_10x10 hex_20x20 random_400 poly_uniform_400 poly_lognormal_500)
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"
export DEMCAL_CACHE_DIR="$out/consolidation-cache"
rm -rf "$DEMCAL_CACHE_DIR"
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)," \
  "load $(cut -d' ' -f1-3 /proc/loadavg); DEMCAL_SIMD=${DEMCAL_SIMD:-auto}"
echo
echo "| scene | N | trials | calibration / final run (particle-steps) | consolidation steps | wall s | SIMD | Nstep | peak vs 8x Nstep |"
echo "|---|---:|---:|---:|---:|---:|---|---:|---:|"
for scene in "${scenes[@]}"; do
  cfg="$root/configs/$scene.json"
  dir="$out/$scene"
  rm -rf "$dir"
  status=0
  "$build/demcal" calibrate "$cfg" -o "$dir" -q --jobs 2 > "$dir.log" 2>&1 || status=$?
  if [ ! -f "$dir/params.json" ]; then
    echo "| $scene | | | | | | | | failed (exit $status): $(tail -n 1 "$dir.log" | cut -c1-120) |"
    continue
  fi
  if [ "$status" -ne 0 ]; then
    python3 - "$dir" "$scene" <<'EOF'
import json, sys
d, scene = sys.argv[1:]
p = json.load(open(d + "/params.json"))
run = json.load(open(d + "/run.json"))
print(f"| {scene} | {p['rev']['particles']} | {p['trials']} | no certified answer | | "
      f"{run['wall_time_s']:.1f} | {run['kernel_simd']} | | |")
EOF
    continue
  fi
  read -r n trials ratio steps alpha zt zr peak < <(python3 - "$dir" <<'EOF'
import json, sys
d = sys.argv[1]
p = json.load(open(d + "/params.json"))
rev = p["rev"]
n, steps = rev["particles"], rev["steps"]
print(n, p["trials"], "%.1f" % (p["particle_steps_run"] / (n * steps)), steps,
      rev["dt_ratio"], rev["damping_ratio_translation"], rev["damping_ratio_rotation"],
      p["certificate"]["peak_stress_yy"])
EOF
  )
  "$build/demcal" run "$cfg" --set algorithm.dt_ratio="$alpha" \
    --set algorithm.damping_ratio_translation="$zt" --set algorithm.damping_ratio_rotation="$zr" \
    --set algorithm.steps=$((8 * steps)) -o "$dir/x8" > /dev/null 2>&1 || true
  python3 - "$dir" "$scene" "$n" "$trials" "$ratio" "$steps" "$peak" <<'EOF'
import json, sys
d, scene, n, trials, ratio, steps, peak = sys.argv[1:]
run = json.load(open(d + "/run.json"))
s8 = json.load(open(d + "/x8/summary.json"))
p8 = s8["peak"]["stress_yy"]
dev = "%+.2f %%" % (100 * (float(peak) - p8) / abs(p8))
print(f"| {scene} | {n} | {trials} | {ratio}x | {s8['consolidation']['steps']} | "
      f"{run['wall_time_s']:.1f} | {run['kernel_simd']} | {steps} | {dev} |")
EOF
done
# Where the particle-steps went: trials.jsonl grouped by phase (search trials
# also by the Nstep they ran at), in final runs (particles x calibrated Nstep).
echo
echo "phases (particle-steps / one final run; search@S: search trials at S steps):"
for scene in "${scenes[@]}"; do
  [ -f "$out/$scene/params.json" ] || continue
  python3 - "$out/$scene" "$scene" <<'EOF2'
import collections, json, sys
d, scene = sys.argv[1:]
p = json.load(open(d + "/params.json"))
final = p["rev"]["particles"] * p["rev"]["steps"]
phases = collections.OrderedDict()
for line in open(d + "/trials.jsonl"):
    t = json.loads(line)
    key = t["phase"] + ("@%d" % t["params"]["steps"] if t["phase"] == "search" else "")
    c = phases.setdefault(key, [0, 0.0])
    c[0] += 1
    c[1] += t["particle_steps"] / final
print(f"- {scene}: " + "; ".join(f"{k} x{n}: {v:.2f}" for k, (n, v) in phases.items()))
EOF2
done
