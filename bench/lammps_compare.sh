#!/usr/bin/env bash
# Side-by-side throughput of demcal and LAMMPS on the same scene, one core.
#
#   bench/lammps_compare.sh [BUILD_DIR]
#
# BUILD_DIR (default: build/ next to this script's parent) must hold
# bench_side_by_side (cmake .. -DDEMCAL_BUILD_BENCH=ON && make bench_side_by_side).
# Environment knobs:
#   REPS=5            repetitions per engine and size (alternating demcal, LAMMPS)
#   SIZES="100 400 10000 100000"   hexagonal sizes (side = round(sqrt(N)))
#   RANDOM400=1       also the random polydisperse 400-disk scene (0: skip)
#   SPHERES=0         1: then the 3D side by side too (lammps_compare_sphere.sh,
#                     same BUILD_DIR; it needs bench_sphere_side_by_side)
#   CORE=0            the core both engines are pinned to (taskset)
#   PS_TARGET=4e7     particle-steps per timed run (sets the step count; at most
#                     2e5 steps, i.e. 2 % strain of the top wall)
#   KEEP=dir          keep the raw outputs there (default: a temp dir, removed)
#
# For every size the script writes the scene once (positions, radii, masses,
# walls, Δt, damping, skin: bench_side_by_side --write-lammps), then runs
# demcal and LAMMPS alternately, each: pre-load steps, then a timed run.
# Timing excludes set-up in both: demcal times World::step(nsteps), LAMMPS
# reports "Loop time" of the second `run`. Both print the particle contacts
# and the pair virial W = Σ (x_i − x_j) ⊗ f_ij at the end of the run; they
# must agree, or the comparison is not of the same computation.
# The script installs nothing.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
build="${1:-$here/../build}"
REPS="${REPS:-5}"
SIZES="${SIZES:-100 400 10000 100000}"
RANDOM400="${RANDOM400:-1}"
CORE="${CORE:-0}"
PS_TARGET="${PS_TARGET:-4e7}"

if ! command -v lmp >/dev/null 2>&1; then
  echo "lmp (LAMMPS) not found: install it with 'apt-get install lammps' and re-run. Nothing compared."
  exit 0
fi
driver="$build/bench_side_by_side"
if [[ ! -x "$driver" ]]; then
  echo "error: $driver not found; build it: cmake .. -DDEMCAL_BUILD_BENCH=ON && make bench_side_by_side" >&2
  exit 1
fi
for tool in taskset python3; do
  command -v "$tool" >/dev/null 2>&1 || { echo "error: $tool is required" >&2; exit 1; }
done

if [[ -n "${KEEP:-}" ]]; then
  work="$KEEP"; mkdir -p "$work"
else
  work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT
fi
echo "# machine: $(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores; pinned to core $CORE"
export OMP_NUM_THREADS=1
pin=(taskset -c "$CORE")

echo "# $(lmp -h | grep -m1 'Large-scale' | sed 's/^ *//')"
echo "# demcal driver: $driver"
echo "# reps=$REPS particle-steps per run ~ $PS_TARGET"
echo "# start $(date -u +%FT%TZ), load average $(cut -d' ' -f1-3 /proc/loadavg)"

results="$work/results.tsv"
: >"$results"

run_case() {  # kind n
  local kind="$1" n="$2"
  local steps preload
  # ~PS_TARGET particle-steps, at most 2e5 steps (2 % top-wall strain).
  steps=$(python3 -c "print(min(200000, max(100, round($PS_TARGET / $n))))")
  preload=$(python3 -c "print(min(2000, max(200, round(2e7 / $n))))")
  local prefix="$work/${kind}_$n"
  "$driver" --scene "$kind" --n "$n" --steps "$steps" --preload "$preload" \
    --write-lammps "$prefix" --no-run
  echo "# $kind N=$n: $steps timed steps after $preload pre-load steps" >&2
  for ((rep = 1; rep <= REPS; rep++)); do
    # demcal
    local line
    line=$("${pin[@]}" "$driver" --scene "$kind" --n "$n" --steps "$steps" --preload "$preload")
    echo "$line" >>"$work/demcal_${kind}_$n.log"
    python3 - "$kind" "$n" "$line" >>"$results" <<'PY'
import sys
kind, n, line = sys.argv[1], sys.argv[2], sys.argv[3]
kv = dict(t.split("=", 1) for t in line.split())
print("\t".join([kind, n, "demcal", kv["particles"], kv["steps"], kv["seconds"],
                 kv["contacts"], kv["Wxx_pair"], kv["Wyy_pair"], kv["cpu_seconds"]]))
PY
    # LAMMPS
    local out="$work/lammps_${kind}_${n}_$rep.txt"
    "${pin[@]}" lmp -in "$here/lammps/in.compress" -var prefix "$prefix" -log none -screen "$out"
    python3 - "$kind" "$n" "$out" >>"$results" <<'PY'
import re, sys
kind, n, path = sys.argv[1:4]
text = open(path).read()
loops = re.findall(r"Loop time of ([0-9.eE+-]+) on 1 procs for (\d+) steps with (\d+) atoms", text)
if len(loops) < 2:
    sys.exit("LAMMPS run failed, see " + path)
sec, steps, atoms = loops[-1]
cpu_pct = re.findall(r"([0-9.]+)% CPU use", text)
cpu = float(sec) * float(cpu_pct[-1]) / 100.0
# last thermo row before the last "Loop time": step atoms mass contacts Wxx Wyy ke
block = text.rsplit("Loop time", 1)[0].strip().splitlines()
row = block[-1].split()
print("\t".join([kind, n, "lammps", atoms, steps, sec, str(int(float(row[3]))), row[4], row[5],
                 str(cpu)]))
PY
  done
}

for n in $SIZES; do run_case hex "$n"; done
if [[ "$RANDOM400" == "1" ]]; then run_case random 400; fi
echo "# end $(date -u +%FT%TZ), load average $(cut -d' ' -f1-3 /proc/loadavg)"

python3 - "$results" <<'PY'
import statistics as st, sys
rows = [l.split("\t") for l in open(sys.argv[1]).read().splitlines() if l]
cases = []
for r in rows:
    if (r[0], r[1]) not in cases:
        cases.append((r[0], r[1]))
def summary(kind, n, eng, col):
    rs = [r for r in rows if r[0] == kind and r[1] == n and r[2] == eng]
    rates = [int(r[3]) * int(r[4]) / float(r[col]) for r in rs]
    last = rs[-1]
    return dict(N=int(last[3]), steps=int(last[4]), med=st.median(rates), lo=min(rates),
                hi=max(rates), secs=st.median(float(r[col]) for r in rs), contacts=last[6],
                wxx=float(last[7]), wyy=float(last[8]), reps=len(rs))
f = lambda s: f"{s['med']:.3e} [{s['lo']:.3e}, {s['hi']:.3e}]"
for title, col in (("wall-clock time", 5), ("CPU time of the process (robust to preemption)", 9)):
    print(f"\n### particle-steps/s from {title}\n")
    print("| scene | N | steps | demcal median [min, max] | LAMMPS median [min, max] | ratio demcal/LAMMPS | run s (d / L) |")
    print("|---|---|---|---|---|---|---|")
    for kind, n in cases:
        d, l = summary(kind, n, "demcal", col), summary(kind, n, "lammps", col)
        print(f"| {kind} | {d['N']} | {d['steps']} | {f(d)} | {f(l)} | {d['med']/l['med']:.2f} "
              f"| {d['secs']:.2f} / {l['secs']:.2f} |")
print("\n### same computation? (end of the last run of each engine)\n")
print("| scene | N | contacts demcal / LAMMPS | W_xx pair N·m demcal / LAMMPS | W_yy pair N·m demcal / LAMMPS |")
print("|---|---|---|---|---|")
for kind, n in cases:
    d, l = summary(kind, n, "demcal", 5), summary(kind, n, "lammps", 5)
    print(f"| {kind} | {d['N']} | {d['contacts']} / {l['contacts']} | {d['wxx']:.5g} / {l['wxx']:.5g} "
          f"| {d['wyy']:.5g} / {l['wyy']:.5g} |")
print(f"\n(reps per cell: {summary(*cases[0], 'demcal', 5)['reps']}; spread = min and max over the reps)")
PY
if [[ "${SPHERES:-0}" == 1 ]]; then
  echo
  echo "# 3D: spheres (bench/lammps_compare_sphere.sh)"
  "$here/lammps_compare_sphere.sh" "$build"
fi
