#!/usr/bin/env bash
# Cost of the exported 3D LAMMPS deck (triaxial loading) over a bare 3D
# granular step, serial and under MPI (issue #16, item 1; the 2D tool is
# bench/lammps_overhead.sh). For each prototype size N:
#   deck = `demcal export PARAMS --particles N EXPORT_FLAGS` (a 3D params.json;
#          default --consolidate-in demcal: the data file holds the state
#          consolidated to sigma3, so the loading starts static and no warm-up
#          run is needed), run for STEPS loading steps;
#   bare = the same data file, pair style, nve/sphere and viscous damping (the
#          deck's own `fix dampt` line), with the six walls as static
#          `fix wall/gran` planes where the deck's walls start (no servo, no
#          output): the least a triaxial test needs.
# Prints LAMMPS' "Loop time", the Pair and Modify shares, the process CPU
# time and the load average (the machine may be shared: compare runs taken
# side by side), and with CALLGRIND="S1 S2" the instructions per step
# (valgrind callgrind, Ir, user space) of each kind: the difference of a run
# of S2 and one of S1 steps from the same start, divided by S2 - S1, so that
# start-up, reading and setup cancel (reports/engines.md §11.1's method).
#
#   bench/lammps_overhead_3d.sh PARAMS.json [BUILD_DIR]
# Environment: SIZES="500 20000" STEPS=2000 NP="1 2" REPEAT=1 KEEP=dir
#   REUSE=1 with KEEP: keep the exported decks of an earlier call (a 20 000-
#   sphere consolidation by demcal takes minutes)
#   EXPORT_FLAGS (default "--consolidate-in demcal")
#   OLD_BUILD=dir: a second demcal build; its deck of the same data file runs
#   as "old", alternating with bare and deck
#   CALLGRIND="S1 S2": instructions per step instead of timed runs (serial)
#   MPI_FLAGS: extra mpirun flags (e.g. "--bind-to none")
# Installs nothing; needs lmp (mpirun for NP > 1, valgrind for CALLGRIND).
set -euo pipefail
params="${1:?usage: bench/lammps_overhead_3d.sh PARAMS.json [BUILD_DIR]}"
build="${2:-$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/build}"
SIZES="${SIZES:-500 20000}"
STEPS="${STEPS:-2000}"
NP="${NP:-1 2}"
EXPORT_FLAGS="${EXPORT_FLAGS:---consolidate-in demcal}"
command -v lmp >/dev/null || { echo "lmp (LAMMPS) not found: apt-get install lammps"; exit 0; }
params="$(realpath "$params")"
build="$(realpath "$build")"
[[ -n "${OLD_BUILD:-}" ]] && OLD_BUILD="$(realpath "$OLD_BUILD")"
if [[ -n "${KEEP:-}" ]]; then work="$KEEP"; mkdir -p "$work"; else
  work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT; fi
echo "# $(lmp -h | grep -m1 'Large-scale' | sed 's/^ *//'); $(nproc) cores; start $(date -u +%FT%TZ)"
for n in $SIZES; do
  d="$work/n$n"; mkdir -p "$d"
  if [[ "${REUSE:-0}" != 1 || ! -f "$d/deck.lammps" ]]; then
    # shellcheck disable=SC2086
    "$build/demcal" export "$params" --particles "$n" $EXPORT_FLAGS -o "$d/deck.lammps" >/dev/null 2>&1
  fi
  kinds="bare deck"
  if [[ -n "${OLD_BUILD:-}" ]]; then
    if [[ "${REUSE:-0}" != 1 || ! -f "$d/old.lammps" ]]; then
      # shellcheck disable=SC2086
      "$OLD_BUILD/demcal" export "$params" --particles "$n" $EXPORT_FLAGS -o "$d/old/deck.lammps" >/dev/null 2>&1
      cmp -s "$d/old/deck.lammps.data" "$d/deck.lammps.data" || { echo "OLD_BUILD wrote another data file"; exit 1; }
      cp "$d/old/deck.lammps" "$d/old.lammps"
    fi
    kinds="bare old deck"
  fi
  get() { sed -n "s/^variable $1 *equal \([^ ]*\).*/\1/p" "$d/deck.lammps" | head -1; }
  damp=$(grep -m1 '^fix *dampt all viscous' "$d/deck.lammps" || true)
  cat > "$d/bare.lammps" <<EOF
# bare 3D granular step: the deck's particles, contact law, integration and
# damping; six static plane walls where the deck's start; no servo, no output
variable run_steps index 1000
units           si
dimension       3
boundary        f f f
atom_style      sphere
atom_modify     map array
comm_modify     vel yes
newton          off
read_data       deck.lammps.data
$(grep -m1 '^pair_style' "$d/deck.lammps" | sed "s/\${kn}/$(get kn)/; s/\${kt}/$(get kt)/; s/\${mu}/$(get mu)/")
pair_coeff      * *
$(grep -m1 '^neighbor' "$d/deck.lammps")
$(grep -m1 '^neigh_modify' "$d/deck.lammps")
timestep        $(get dt)
fix             integrate all nve/sphere
fix             wx all wall/gran hooke/history $(get kn_wall) $(get kt_wall) 0 0 $(get mu_wall) 0 xplane $(get xmin0) $(get xmax0)
fix             wy all wall/gran hooke/history $(get kn_wall) $(get kt_wall) 0 0 $(get mu_wall) 0 yplane $(get ymin0) $(get ymax0)
fix             wz all wall/gran hooke/history $(get kn_wall) $(get kt_wall) 0 0 $(get mu_wall) 0 zplane $(get zmin0) $(get zmax0)
${damp}
thermo          1000
run             \${run_steps}
EOF
  if [[ -n "${CALLGRIND:-}" ]]; then
    read -r s1 s2 <<< "$CALLGRIND"
    for kind in $kinds; do
      ir=()
      for s in "$s1" "$s2"; do
        (cd "$d" && valgrind --tool=callgrind --callgrind-out-file="cg.$kind.$s" \
           lmp -var run_steps "$s" -in "$kind.lammps" -log "log.cg.$kind.$s" -screen none \
           >/dev/null 2>"cg.$kind.$s.err")
        ir+=("$(sed -n 's/^summary: *//p' "$d/cg.$kind.$s")")
      done
      echo "N=$n $kind: Ir ${ir[0]} ($s1 steps) ${ir[1]} ($s2 steps): $(( (ir[1] - ir[0]) / (s2 - s1) )) per step"
    done
    echo "# $(uptime)"
    continue
  fi
  for rep in $(seq "${REPEAT:-1}"); do
  for np in $NP; do
    for kind in $kinds; do
      launch=(lmp); [[ "$np" -gt 1 ]] && launch=(mpirun --allow-run-as-root --oversubscribe ${MPI_FLAGS:-} -np "$np" lmp)
      load=$(cut -d' ' -f1 /proc/loadavg)
      cpu=$( { cd "$d" && /usr/bin/time -f "%U %S" "${launch[@]}" -var run_steps "$STEPS" -in "$kind.lammps" \
               -log "log.$kind.$np" -screen none >/dev/null; } 2>&1 | tail -1)
      if grep -q "^ERROR" "$d/log.$kind.$np"; then grep -m1 "^ERROR" "$d/log.$kind.$np"; exit 1; fi
      loop=$(sed -n 's/^Loop time of \([^ ]*\).*/\1/p' "$d/log.$kind.$np" | tail -1)
      pair=$(awk '/^Pair /{p=$(NF)} END{print p}' "$d/log.$kind.$np")
      modify=$(awk '/^Modify /{m=$(NF)} END{print m}' "$d/log.$kind.$np")
      echo "N=$n np=$np $kind: loop ${loop} s, cpu(user sys) ${cpu} s, Pair ${pair} %, Modify ${modify} %, load ${load}"
    done
  done
  done
  echo "# $(uptime)"
done
