#!/usr/bin/env bash
# Side-by-side throughput of demcal's sphere kernel and LAMMPS 3D on the same
# FCC scene, one core (bench_sphere_side_by_side + lammps/in.sphere_compress).
#
#   bench/lammps_compare_sphere.sh [BUILD_DIR]
#
# BUILD_DIR (default: build/) must hold bench_sphere_side_by_side
# (cmake -DDEMCAL_BUILD_BENCH=ON, target bench_sphere_side_by_side).
# Environment knobs:
#   CELLS="4 10 19"   FCC cells per side (4n³ spheres: 256, 4000, 27436)
#   PS_TARGET=2e7     particle-steps per timed run
#   CORE=0            the core both engines are pinned to (taskset)
# Timing excludes set-up in both: demcal times SphereWorld::step(nsteps),
# LAMMPS reports "Loop time" of the second `run`. Both print the particle
# contacts at the end: they must agree, or the comparison is not of the same
# computation. One run each: on a loaded machine say the load (printed).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
build="${1:-$here/../build}"
CELLS="${CELLS:-4 10 19}"
PS_TARGET="${PS_TARGET:-2e7}"
CORE="${CORE:-0}"
if ! command -v lmp >/dev/null 2>&1; then
  echo "lmp (LAMMPS) not found: nothing compared."
  exit 0
fi
driver="$build/bench_sphere_side_by_side"
[[ -x "$driver" ]] || { echo "error: $driver not found" >&2; exit 1; }
work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT
export OMP_NUM_THREADS=1
pin=(taskset -c "$CORE")
echo "# machine: $(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores; pinned to core $CORE"
echo "# $(lmp -h | grep -m1 'Large-scale' | sed 's/^ *//')"
echo "# start $(date -u +%FT%TZ), load average $(cut -d' ' -f1-3 /proc/loadavg)"
printf "%8s %10s %14s %14s %8s %10s\n" spheres steps demcal_ps/s lammps_ps/s ratio contacts
for n in $CELLS; do
  spheres=$((4 * n * n * n))
  steps=$(python3 -c "print(max(200, int(float('$PS_TARGET') / $spheres)))")
  pre=$((steps / 10))
  "$driver" --cells "$n" --write-lammps "$work/fcc$n" --no-run
  d=$("${pin[@]}" "$driver" --cells "$n" --steps "$steps" --preload "$pre")
  dps=$(sed -n 's/.*particle_steps_per_s=\([^ ]*\).*/\1/p' <<<"$d")
  dcon=$(sed -n 's/.*contacts=\([^ ]*\).*/\1/p' <<<"$d")
  (cd "$work" && "${pin[@]}" lmp -in "$here/lammps/in.sphere_compress" -var prefix "fcc$n" \
      -var npre "$pre" -var nsteps "$steps" -log "log$n" -screen none >/dev/null)
  loop=$(sed -n 's/^Loop time of \([^ ]*\).*/\1/p' "$work/log$n" | tail -1)
  lcon=$(awk '/^ *Step/{h=1;next} h&&NF==4&&$1~/^[0-9]+$/{c=$3} /^Loop time/{h=0} END{print c}' "$work/log$n")
  lps=$(python3 -c "print('%.3g' % ($spheres * $steps / $loop))")
  ratio=$(python3 -c "print('%.2f' % ($dps / ($spheres * $steps / $loop)))")
  printf "%8d %10d %14.3g %14s %8s %10s\n" "$spheres" "$steps" "$dps" "$lps" "$ratio" "$dcon/$lcon"
done
echo "# end $(date -u +%FT%TZ), load average $(cut -d' ' -f1-3 /proc/loadavg)"
