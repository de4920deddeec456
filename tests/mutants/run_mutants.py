#!/usr/bin/env python3
"""Mutation check of the kernel tests: does some test fail when the code is wrong?

    tests/mutants/run_mutants.py BUILD_DIR [MUTANTS_JSON] [--filter GTEST_FILTER]

Each mutant of MUTANTS_JSON (default: sphere_kernel.json beside this script)
is one small, deliberate error in the source tree -- {"name", "file", "old",
"new"}, "old" replaced by "new" where it occurs exactly once. For each, in
turn: the file is changed, BUILD_DIR's demcal_tests is rebuilt, the tests of
the filter run (default DEFAULT_FILTER below: the sphere kernel's suites and
the 3D scene's and scoring's that read it; a mutant may name its own
"filter"), and the file is put back. A mutant no test notices (SURVIVED) is a fact of the code no
test pins, or an error that changes nothing measurable (say which, in
reports/mutants-3d.md).

It edits the source tree it belongs to: run it in a clean scratch clone
(git clone . /tmp/m && cmake -S /tmp/m -B /tmp/m/build ...), never in a
tree with work in progress; it refuses a tree with uncommitted changes.
Each mutant costs one rebuild of the changed file and the test run (about
half a minute for the kernel with ccache, minutes for a widely included
header).
"""
import json
import os
import subprocess
import sys
import time

DEFAULT_FILTER = ("Sphere*:Triaxial*:ParticleScales*:Config3D*:Chatter3D*:ScoreDiagnosis3d*:"
                  "ScoringRealRuns*:KernelContactDamping*")
here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))


def main():
    args = sys.argv[1:]
    flt = None
    if "--filter" in args:
        k = args.index("--filter")
        flt = args[k + 1]
        del args[k:k + 2]
    if not args:
        print(__doc__, file=sys.stderr)
        return 2
    build = os.path.abspath(args[0])
    listing = args[1] if len(args) > 1 else os.path.join(here, "sphere_kernel.json")
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=root,
                           capture_output=True, text=True).stdout.strip()
    if dirty:
        print("run_mutants.py: the tree has uncommitted changes; run it in a clean clone",
              file=sys.stderr)
        return 2
    survived = 0
    for m in json.load(open(listing)):
        path = os.path.join(root, m["file"])
        text = open(path).read()
        if text.count(m["old"]) != 1:
            print(f"{m['name']}: NOT APPLIED ('old' occurs {text.count(m['old'])} times)")
            survived += 1
            continue
        t0 = time.time()
        try:
            open(path, "w").write(text.replace(m["old"], m["new"]))
            b = subprocess.run(["cmake", "--build", build, "-j2", "--target", "demcal_tests"],
                               capture_output=True, text=True)
            if b.returncode:
                print(f"{m['name']}: BUILD FAILED\n{b.stdout[-2000:]}")
                survived += 1
                continue
            f = flt or m.get("filter", DEFAULT_FILTER)
            r = subprocess.run([os.path.join(build, "demcal_tests"), "--gtest_filter=" + f,
                                "--gtest_brief=1"], capture_output=True, text=True)
        finally:
            open(path, "w").write(text)
        failed = sorted({line.split()[3] for line in r.stdout.splitlines()
                         if line.startswith("[  FAILED  ]") and "(" in line})
        verdict = "killed" if r.returncode else "SURVIVED"
        survived += r.returncode == 0
        print(f"{m['name']}: {verdict} ({time.time() - t0:.0f} s) {' '.join(failed)}", flush=True)
    # Leave the build as the tree is.
    subprocess.run(["cmake", "--build", build, "-j2", "--target", "demcal_tests"],
                   capture_output=True, text=True)
    return 1 if survived else 0


if __name__ == "__main__":
    sys.exit(main())
