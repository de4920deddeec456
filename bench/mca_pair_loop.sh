#!/bin/bash
# What a CPU model says a pair pass's slot loop should cost: the common
# path of one slot-vector (for the sphere kernel: at least one lane
# touching, no lane sliding, no lane turned far; one root, two divisions)
# cut from a built binary and given to llvm-mca, which simulates it on the
# named CPU's scheduling model (ports, latencies, scheduler and queue
# sizes; every load an L1 hit, every branch predicted). Machine-independent: it needs no hardware counters
# (there are none in the test machines' VMs) and runs on any x86-64 host.
#
#   bench/mca_pair_loop.sh [BIN] [MCPU]
#   e.g. bench/mca_pair_loop.sh build/bench_sphere_side_by_side znver3
#
# BIN: a binary holding the sphere kernel (default
# build/bench_sphere_side_by_side); MCPU: an llvm-mca -mcpu (default znver3,
# AMD Zen 3; `llvm-mca -mcpu=help` lists them). Environment: FUNC (default
# pairs_avx2; pairs_avx512 for the AVX-512 pass, on a CPU model that has
# it), SRC (default sphere_contact.cpp: the source file whose FUNC is meant,
# as the 2D kernel has a function of the same name: SRC=contact.cpp for
# it), ROOTS and DIVS (the roots and divisions the common path must hold:
# default 1 and 2, the sphere law's; the 2D law's are 1 and 1), KEEP (a
# folder to keep the extracted loop in). Needs objdump, readelf, python3 and llvm-mca
# (Debian: binutils, python3, llvm).
#
# How the path is cut: the slot loop is the function's backward conditional
# branch whose body holds the square root; inside it, a forward conditional
# branch to a target inside the body skips a rare block (a sliding lane, a
# far turn: `if (any(...))` in sphere_contact.cpp), so the common path jumps
# over it; a branch out of the body (no lane touching) is not taken. The
# script checks the result against the law's count (ROOTS, DIVS: for the
# sphere law, sphere_contact.cpp's file comment) and stops if the layout was
# not understood.
set -euo pipefail
bin=${1:-build/bench_sphere_side_by_side}
mcpu=${2:-znver3}
func=${FUNC:-pairs_avx2}
src=${SRC:-sphere_contact.cpp}
for t in objdump readelf python3 llvm-mca; do
  command -v "$t" > /dev/null || { echo "mca_pair_loop.sh: $t not found (apt-get install binutils python3 llvm)" >&2; exit 2; }
done
[ -f "$bin" ] || { echo "mca_pair_loop.sh: $bin: no such file" >&2; exit 2; }
if ! echo nop | llvm-mca -mcpu="$mcpu" > /dev/null 2>&1; then
  echo "mca_pair_loop.sh: llvm-mca knows no CPU \"$mcpu\" (llvm-mca -mcpu=help lists them)" >&2
  exit 2
fi
if [ -n "${KEEP:-}" ]; then
  work=$KEEP
  mkdir -p "$work"
else
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
fi

# The function's address and size: the first symbol named FUNC after the
# FILE symbol of SRC (local symbols follow their file's in the table).
# (In the mangled name the function's own name comes with its length before
# it, e.g. 10pairs_avx2, so no longer name that ends in FUNC matches.)
read -r start size < <(readelf -sW "$bin" | awk -v src="$src" -v f="$func" '
  $4 == "FILE" { infile = ($8 == src) }
  infile && $4 == "FUNC" && index($8, length(f) f "ERK") { print $2, $3; exit }') || true
[ -n "${start:-}" ] || { echo "mca_pair_loop.sh: no $func in $src's symbols of $bin" >&2; exit 2; }
stop=$(printf '0x%x' $((0x$start + size)))
objdump -d --no-show-raw-insn --start-address="0x$start" --stop-address="$stop" "$bin" > "$work/func.s"

python3 - "$work/func.s" "$work/common.s" "${ROOTS:-1}" "${DIVS:-2}" << 'EOF'
import re, sys
lines = []
for l in open(sys.argv[1]):
    m = re.match(r'\s*([0-9a-f]+):\s+(.*)$', l)
    if m:
        lines.append((int(m.group(1), 16), re.sub(r'\s*<[^>]*>', '', m.group(2)).strip()))
def branch(text):
    m = re.match(r'(j[a-z]+)\s+([0-9a-f]+)$', text)
    return (m.group(1), int(m.group(2), 16)) if m else None
addrs = [a for a, _ in lines]
# The slot loop: a backward conditional branch whose body holds the root.
loop = None
for k, (a, t) in enumerate(lines):
    b = branch(t)
    if b and b[0] != 'jmp' and b[1] < a:
        body = [x for x in lines if b[1] <= x[0] <= a]
        if any('vsqrtpd' in x[1] for x in body) and (loop is None or len(body) < len(loop)):
            loop = body
if loop is None:
    sys.exit('mca_pair_loop.sh: no loop with a square root in the function')
lo, hi = loop[0][0], loop[-1][0]
out, skip_to = [], None
for a, t in loop:
    if skip_to is not None and a < skip_to:
        continue
    skip_to = None
    b = branch(t)
    if b:
        if b[0] == 'jmp':  # an unconditional jump inside the loop: not this layout
            sys.exit(f'mca_pair_loop.sh: a jmp at {a:#x} inside the slot loop: '
                     'the loop\'s layout was not understood')
        if lo < b[1] <= hi and b[1] > a:
            skip_to = b[1]  # a rare block: the common path jumps over it
        continue            # branches themselves are left out
    out.append(t)
text = '\n'.join(out) + '\n'
roots, divs = text.count('vsqrtpd'), text.count('vdivpd')
want = (int(sys.argv[3]), int(sys.argv[4]))
if (roots, divs) != want:
    sys.exit(f'mca_pair_loop.sh: the cut path has {roots} roots and {divs} divisions, '
             f'not {want[0]} and {want[1]}: the loop\'s layout was not understood')
open(sys.argv[2], 'w').write(text)
print(f'slot loop {lo:#x}..{hi:#x}: {len(loop)} instructions, common path {len(out)} '
      f'(roots {roots}, divisions {divs})')
EOF

mca() { llvm-mca -mcpu="$mcpu" -iterations=400 "$@" "$work/common.s" 2>/dev/null; }
mca -instruction-info=false -resource-pressure=false | grep -E 'Instructions:|Total Cycles:|Total uOps:|uOps Per Cycle|Block RThroughput'
echo "cycles per slot-vector (simulated): $(mca -instruction-info=false -resource-pressure=false |
  awk '/Iterations:/ {n = $2} /Total Cycles:/ {printf "%.1f", $3 / n}')"
# Multiply-class µops (the FP pipes that take them are the scarce ones).
echo "multiplies and FMAs per slot-vector: $(grep -cE '^v(mul|f[n]?m(add|sub))' "$work/common.s")"
mca -all-stats -instruction-info=false -resource-pressure=false | sed -n '/Dynamic Dispatch Stall Cycles/,/^$/p'
mca -instruction-info=false -timeline=false | sed -n '/^Resources:/,/^Resource pressure by instruction/p' | sed '$d'
if [ -n "${KEEP:-}" ]; then echo "(the extracted path: $work/common.s)"; fi
