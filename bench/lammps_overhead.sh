#!/usr/bin/env bash
# Cost of the exported LAMMPS deck over a bare granular step, serial and
# under MPI (issue #16). For each prototype size N:
#   deck  = `demcal export` of PARAMS for N particles, run for STEPS steps;
#   bare  = the same data file, pair style, nve/sphere disc, viscous damping
#           and enforce2d, with the four walls as static `fix wall/gran`
#           planes (the least a biaxial test needs; no servo, no output).
# Prints LAMMPS' "Loop time", the Pair and Modify shares and the process
# CPU time, and the load average (the machine may be shared: compare CPU
# times and shares, and rerun on a quiet machine).
#
#   bench/lammps_overhead.sh PARAMS.json [BUILD_DIR]
# Environment: SIZES="400 20000" STEPS=5000 NP="1 2" REPEAT=1 KEEP=dir
#   REPEAT=3 alternates serial and MPI runs three times (on a shared machine
#   the load changes between runs: compare runs taken side by side)
#   MPI_FLAGS="--mca mpi_yield_when_idle 1 --bind-to none" on a machine shared
#   with other jobs (OpenMPI's ranks otherwise busy-wait pinned to a core
#   another process holds: 5x slower than serial at load 8 on 2 cores)
#   EXPORT_FLAGS="--no-consolidate" (the generated packing as it is: no
#   minutes of consolidation before a timing)
#   WARM=steps: first run the deck that many steps (its restart), then time
#   every kind from that state: the decks continue the run, bare starts from
#   the restart with its static walls where the deck's walls are. Without it
#   a --no-consolidate prototype (walls on the generated lattice, contacts
#   barely touching) is compressed by the deck's servo but not by bare's
#   static walls, and the pair loop does more work in the deck (active
#   contacts) than in bare: physics, not the deck's machinery.
#   OLD_BUILD=dir: a second demcal build (e.g. a worktree at an older
#   commit); its deck for the same data file runs as "old", alternating with
#   bare and deck, so that a change to the deck is timed side by side
#   CORE=c: pin the serial runs to core c (taskset -c c), so that the
#   kinds alternate on the same core (a shared machine: pick the quietest)
# Installs nothing; needs lmp (and mpirun for NP > 1).
set -euo pipefail
params="${1:?usage: bench/lammps_overhead.sh PARAMS.json [BUILD_DIR]}"
build="${2:-$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/build}"
SIZES="${SIZES:-400 20000}"
STEPS="${STEPS:-5000}"
NP="${NP:-1 2}"
command -v lmp >/dev/null || { echo "lmp (LAMMPS) not found: apt-get install lammps"; exit 0; }
params="$(realpath "$params")"
if [[ -n "${KEEP:-}" ]]; then work="$KEEP"; mkdir -p "$work"; else
  work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT; fi
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
echo "# $(lmp -h | grep -m1 'Large-scale' | sed 's/^ *//'); $(nproc) cores; start $(date -u +%FT%TZ)"
for n in $SIZES; do
  d="$work/n$n"; mkdir -p "$d"
  "$build/demcal" export "$params" --particles "$n" ${EXPORT_FLAGS:-} -o "$d/deck.lammps" >/dev/null 2>&1
  kinds="bare deck"
  if [[ -n "${OLD_BUILD:-}" ]]; then
    "$OLD_BUILD/demcal" export "$params" --particles "$n" ${EXPORT_FLAGS:-} -o "$d/old/deck.lammps" >/dev/null 2>&1
    cmp -s "$d/old/deck.lammps.data" "$d/deck.lammps.data" || { echo "OLD_BUILD wrote another data file"; exit 1; }
    cp "$d/old/deck.lammps" "$d/old.lammps"; kinds="bare old deck"
  fi
  # the deck's own numbers, for the bare run
  get() { sed -n "s/^variable $1 *equal \([^ ]*\).*/\1/p" "$d/deck.lammps" | head -1; }
  gamma=$(sed -n 's/^fix *dampt all viscous \([^ ]*\).*/\1/p' "$d/deck.lammps")
  dens=$(sed -n 's/^set .*density\/disc \([^ ]*\)/\1/p' "$d/deck.lammps")
  skin=$(sed -n 's/^neighbor *\([^ ]*\) bin/\1/p' "$d/deck.lammps")
  xl=$(get xl0); xr=$(get xr0); yt=$(get yt0); from=0; deck_args=(); total="$STEPS"
  if [[ "${WARM:-0}" -gt 0 ]]; then
    (cd "$d" && lmp -in deck.lammps -var run_steps "$WARM" -var restart_out warm.restart \
       -log log.warm -screen none >/dev/null)
    read -r -a deck_args < "$d/warm.restart.args"
    xl=$(sed -n 's/.*-var xl_now \([^ ]*\).*/\1/p' "$d/warm.restart.args")
    xr=$(sed -n 's/.*-var xr_now \([^ ]*\).*/\1/p' "$d/warm.restart.args")
    # the top wall at the restart: yb0 + H of the last thermo row (step dt time epsyy pt pl pr W H ke)
    yt=$(awk -v yb="$(get yb0)" '/^Loop time/{printf "%.17g\n", yb+h; exit} $1 ~ /^[0-9]+$/ && NF == 10 {h=$9}' "$d/log.warm")
    from=1; total=$((WARM + STEPS))
  fi
  sed -e "s/@DT@/$(get dt)/; s/@KN@/$(get kn)/; s/@KT@/$(get kt)/; s/@MU@/$(get mu)/" \
      -e "s/@KW@/$(get kn_wall)/; s/@KTW@/$(get kt_wall)/; s/@XL@/$xl/; s/@XR@/$xr/; s/@YB@/$(get yb0)/" \
      -e "s/@YT@/$yt/; s/@GAMMA@/${gamma:-0}/; s/@DENS@/$dens/; s/@SKIN@/$skin/; s/@FROM@/$from/" \
      "$here/lammps/in.bare" > "$d/bare.lammps"
  for rep in $(seq "${REPEAT:-1}"); do
  for np in $NP; do
    for kind in $kinds; do
      launch=(lmp); [[ -n "${CORE:-}" ]] && launch=(taskset -c "$CORE" lmp)
      [[ "$np" -gt 1 ]] && launch=(mpirun --allow-run-as-root --oversubscribe ${MPI_FLAGS:-} -np "$np" lmp)
      load=$(cut -d' ' -f1 /proc/loadavg)
      if [[ "$kind" == bare ]]; then args=(-var run_steps "$STEPS"); else
        args=("${deck_args[@]}" -var run_steps "$total" -var restart_out timed.restart); fi
      cpu=$( { cd "$d" && /usr/bin/time -f "%U %S" "${launch[@]}" "${args[@]}" -in "$kind.lammps" \
               -log "log.$kind.$np" -screen none >/dev/null; } 2>&1 | tail -1)
      if grep -q "^ERROR" "$d/log.$kind.$np"; then grep -m1 "^ERROR" "$d/log.$kind.$np"; exit 1; fi
      loop=$(sed -n 's/^Loop time of \([^ ]*\).*/\1/p' "$d/log.$kind.$np")
      pair=$(awk '/^Pair /{print $(NF)}' "$d/log.$kind.$np")
      modify=$(awk '/^Modify /{print $(NF)}' "$d/log.$kind.$np")
      echo "N=$n np=$np $kind: loop ${loop} s, cpu(user sys) ${cpu} s, Pair ${pair} %, Modify ${modify} %, load ${load}"
    done
  done
  done
  echo "# $(uptime)"
done
