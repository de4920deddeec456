#!/usr/bin/env bash
# MPI speed-up of the LAMMPS decks' stage 1 (their own consolidation, issue
# #16 item 2): each deck run serially and under `mpirun -np 2`, alternating,
# ROUNDS times; prints wall and CPU time and the sum of LAMMPS' loop times.
#   bench/lammps_stage1_mpi.sh DECK_DIR...
# A DECK_DIR holds deck.lammps from `demcal export ... --consolidate-in deck`.
# Only stage 1 runs (`-var run_steps 0`: no loading). CAP=steps edits the
# deck's cons_max_steps (into deck_cap.lammps) for a gas that takes 10^5
# steps to settle: the stage then stops at CAP (exit 2 by design) and the
# timing is per step (CAP >= 4 * cons_check = 800: the stage switches to
# critical damping after a quarter of it). Installs nothing; needs lmp and mpirun.
set -euo pipefail
command -v lmp >/dev/null || { echo "lmp (LAMMPS) not found: apt-get install lammps"; exit 0; }
command -v mpirun >/dev/null || { echo "mpirun not found: apt-get install openmpi-bin"; exit 0; }
ROUNDS="${ROUNDS:-2}"
echo "# $(uptime)"
for r in $(seq "$ROUNDS"); do
  for d in "$@"; do
    deck=deck.lammps
    if [[ -n "${CAP:-}" ]]; then
      sed "s/^variable cons_max_steps equal .*/variable cons_max_steps equal $CAP/" "$d/deck.lammps" >"$d/deck_cap.lammps"
      deck=deck_cap.lammps
    fi
    for np in 1 2; do
      run=(lmp); [[ $np == 2 ]] && run=(mpirun --allow-run-as-root -np 2 lmp)
      t=$( { (cd "$d" && /usr/bin/time -f "wall %e s user %U s" "${run[@]}" -in "$deck" \
              -var run_steps 0 -log "log.np$np.r$r.lammps" -screen none >/dev/null) 2>&1 || true; } | tail -1)
      loop=$(awk '/^Loop time/ {s += $4; n += $9} END {printf "%.3f s over %d steps", s, n}' "$d/log.np$np.r$r.lammps")
      echo "$(basename "$d") np $np round $r: $t, loop $loop"
    done
  done
done
echo "# $(uptime)"
