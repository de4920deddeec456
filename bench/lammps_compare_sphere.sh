#!/usr/bin/env bash
# Side-by-side throughput of demcal's sphere kernel and LAMMPS 3D on the same
# FCC scene, one core (bench_sphere_side_by_side + lammps/in.sphere_compress).
#
#   bench/lammps_compare_sphere.sh [BUILD_DIR]
#
# BUILD_DIR (default: build/) must hold bench_sphere_side_by_side
# (cmake -DDEMCAL_BUILD_BENCH=ON, target bench_sphere_side_by_side).
# Environment knobs:
#   CELLS="4 10 29"    FCC cells per side (4n³ spheres: 256, 4000, 97556)
#   PS_TARGET=2e7      particle-steps per timed run
#   REPS=3             rounds; each round runs, alternately, demcal on every
#                      path of PATHS, LAMMPS, and (if THREADS > 1) demcal on
#                      THREADS threads; medians over the rounds are printed
#   PATHS="default avx2"  demcal SIMD paths (DEMCAL_SIMD; default = the widest)
#                      (DEMCAL_GATHER=hardware|emulated, if set, passes through
#                      to every demcal run; the end line says how each path
#                      gathered)
#   THREADS=2          threads of the extra demcal run (pinned to cores 0..T-1;
#                      1: no such run), only from THREADS_MIN spheres on
#   THREADS_MIN=50000  (small samples run single-threaded: a calibration
#                      runs trials in parallel instead)
#   CORE=0             the core the one-core runs are pinned to (taskset)
#   BASELINE=binary    another build of bench_sphere_side_by_side (e.g. of an
#                      older commit), run on every path of PATHS in the same
#                      rounds, alternating with the current one: adds its
#                      rate and the current/baseline speed-up per path
#   KEEP=dir           keep the raw outputs there
# Timing excludes set-up in both: demcal times SphereWorld::step(nsteps),
# LAMMPS reports "Loop time" of the second `run`. The one-core rates are CPU
# time (demcal: clock(); LAMMPS: Loop time × its "% CPU use"), so that a
# busy machine (other processes on the pinned core) slows neither engine's
# figure; the thread speed-up is wall time (2 threads against 1, same round). Both print the particle
# contacts at the end: they must agree, or the comparison is not of the same
# computation. The machine may be shared: the load average is printed at
# the start and the end, and every raw line is kept (KEEP).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
build="${1:-$here/../build}"
CELLS="${CELLS:-4 10 29}"
PS_TARGET="${PS_TARGET:-2e7}"
REPS="${REPS:-3}"
PATHS="${PATHS:-default avx2}"
THREADS="${THREADS:-2}"
THREADS_MIN="${THREADS_MIN:-50000}"
CORE="${CORE:-0}"
BASELINE="${BASELINE:-}"
if ! command -v lmp >/dev/null 2>&1; then
  echo "lmp (LAMMPS) not found: nothing compared."
  exit 0
fi
driver="$build/bench_sphere_side_by_side"
[[ -x "$driver" ]] || { echo "error: $driver not found" >&2; exit 1; }
work="${KEEP:-$(mktemp -d)}"
mkdir -p "$work"
[[ -n "${KEEP:-}" ]] || trap 'rm -rf "$work"' EXIT
export OMP_NUM_THREADS=1
pin=(taskset -c "$CORE")
# (--all: OMP_NUM_THREADS=1, exported above, makes plain nproc say 1)
echo "# machine: $(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc --all) cores; pinned to core $CORE"
echo "# $(lmp -h | grep -m1 'Large-scale' | sed 's/^ *//')"
echo "# start $(date -u +%FT%TZ), load average $(cut -d' ' -f1-3 /proc/loadavg)"
median() { python3 -c "import statistics,sys; print('%.4g' % statistics.median(float(v) for v in sys.argv[1:]))" "$@"; }
field() { sed -n "s/.* $1=\([^ ]*\).*/\1/p" <<<"$2"; }
declare -A gathers=()
header="spheres steps"
for p in $PATHS; do header+=" demcal_${p}_ps/s ratio_${p}"; done
if [[ -n "$BASELINE" ]]; then
  [[ -x "$BASELINE" ]] || { echo "error: $BASELINE not found" >&2; exit 1; }
  for p in $PATHS; do header+=" baseline_${p}_ps/s speedup_${p}"; done
fi
header+=" lammps_ps/s contacts"
# the thread columns: wall-clock rate of the THREADS run and its speed-up
# over the one-thread wall-clock rate of the first path, same rounds
[[ "$THREADS" -gt 1 ]] && header+=" demcal_${THREADS}thr_ps/s speedup_${THREADS}thr"
echo "# medians over $REPS alternating rounds; ratio = demcal/LAMMPS per particle-step"
echo "$header"
for n in $CELLS; do
  spheres=$((4 * n * n * n))
  steps=$(python3 -c "print(max(100, int(float('$PS_TARGET') / $spheres)))")
  pre=$((steps / 10))
  "$driver" --cells "$n" --write-lammps "$work/fcc$n" --no-run
  declare -A rates=() brates=()
  lrates="" trates="" wall1="" dcon="" lcon=""
  for rep in $(seq "$REPS"); do
    for p in $PATHS; do
      if [[ "$p" == default ]]; then env=(env -u DEMCAL_SIMD); else env=(env DEMCAL_SIMD="$p"); fi
      d=$("${env[@]}" "${pin[@]}" "$driver" --cells "$n" --steps "$steps" --preload "$pre")
      echo "$d" >>"$work/raw.txt"
      rates[$p]+=" $(python3 -c "print($spheres * $steps / $(field cpu_seconds "$d"))")"
      [[ "$p" == "${PATHS%% *}" ]] && wall1+=" $(field particle_steps_per_s "$d")"
      dcon=$(field contacts "$d")
      gathers[$p]=$(field gather "$d")
      if [[ -n "$BASELINE" ]]; then
        d=$("${env[@]}" "${pin[@]}" "$BASELINE" --cells "$n" --steps "$steps" --preload "$pre")
        echo "baseline $d" >>"$work/raw.txt"
        brates[$p]+=" $(python3 -c "print($spheres * $steps / $(field cpu_seconds "$d"))")"
      fi
    done
    (cd "$work" && "${pin[@]}" lmp -in "$here/lammps/in.sphere_compress" -var prefix "fcc$n" \
        -var npre "$pre" -var nsteps "$steps" -log "log$n.$rep" -screen none >/dev/null)
    loop=$(sed -n 's/^Loop time of \([^ ]*\).*/\1/p' "$work/log$n.$rep" | tail -1)
    pct=$(sed -n 's/^\([0-9.]*\)% CPU use.*/\1/p' "$work/log$n.$rep" | tail -1)
    loop=$(python3 -c "print($loop * ${pct:-100} / 100)")
    lcon=$(awk '/^ *Step/{h=1;next} h&&NF==4&&$1~/^[0-9]+$/{c=$3} /^Loop time/{h=0} END{print c}' "$work/log$n.$rep")
    echo "engine=lammps particles=$spheres steps=$steps loop_seconds=$loop contacts=$lcon" >>"$work/raw.txt"
    lrates+=" $(python3 -c "print($spheres * $steps / $loop)")"
    if [[ "$THREADS" -gt 1 && "$spheres" -ge "$THREADS_MIN" ]]; then
      d=$(taskset -c "0-$((THREADS - 1))" "$driver" --cells "$n" --steps "$steps" --preload "$pre" \
          --threads "$THREADS")
      echo "$d" >>"$work/raw.txt"
      trates+=" $(field particle_steps_per_s "$d")"
    fi
  done
  lmed=$(median $lrates)
  line="$spheres $steps"
  for p in $PATHS; do
    m=$(median ${rates[$p]})
    line+=" $m $(python3 -c "print('%.2f' % ($m / $lmed))")"
  done
  if [[ -n "$BASELINE" ]]; then
    for p in $PATHS; do
      b=$(median ${brates[$p]})
      line+=" $b $(python3 -c "print('%.2f' % ($(median ${rates[$p]}) / $b))")"
    done
  fi
  line+=" $lmed $dcon/$lcon"
  if [[ -n "$trates" ]]; then
    t=$(median $trates)
    line+=" $t $(python3 -c "print('%.2f' % ($t / $(median $wall1)))")"
  fi
  echo "$line"
  unset rates brates
done
ways=""
for p in $PATHS; do ways+=" $p:${gathers[$p]:-?}"; done
echo "# gathers (path:way):$ways"
echo "# end $(date -u +%FT%TZ), load average $(cut -d' ' -f1-3 /proc/loadavg)"
