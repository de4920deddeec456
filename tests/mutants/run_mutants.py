#!/usr/bin/env python3
"""Mutation check of the kernel tests: does some test fail when the code is wrong?

    tests/mutants/run_mutants.py BUILD_DIR [MUTANTS_JSON] [--filter GTEST_FILTER]

Each mutant of MUTANTS_JSON (default: sphere_kernel.json beside this script)
is one small, deliberate error in the source tree -- {"name", "file", "old",
"new"}, "old" replaced by "new" where it occurs exactly once. A listing is a
JSON list of mutants, or {"filter": GTEST_FILTER, "mutants": [...]} with the
tests its mutants run against (disk_kernel.json, protocols.json,
scoring.json). First the tests run once on the tree as it is: they must
pass, or every mutant would read as noticed. Then for each mutant in turn:
the file is changed, BUILD_DIR's demcal_tests is rebuilt, the tests of the
filter run (--filter, else the mutant's own "filter", else the listing's,
else DEFAULT_FILTER below: the sphere kernel's suites and the 3D scene's and
scoring's that read it), and the file is put back. A mutant no test
notices (SURVIVED) is a fact of the code no test pins, or an error that
changes nothing measurable (say which, in reports/mutants-*.md). Exit
status 0 when every mutant was noticed, 1 when one was not (or could not
be applied or built), 2 on bad use.

It edits the source tree it belongs to: run it in a clean scratch clone
(git clone . /tmp/m && cmake -S /tmp/m -B /tmp/m/build ...), never in a
tree with work in progress; it refuses a tree with uncommitted changes and
a BUILD_DIR configured from another tree. Each mutant costs one rebuild of
the changed file and the test run (about half a minute for the kernel with
ccache, ten minutes for a header most of the library includes).
"""
import json
import os
import signal
import subprocess
import sys
import time

DEFAULT_FILTER = ("Sphere*:Triaxial*:ParticleScales*:Config3D*:Chatter3D*:ScoreDiagnosis3d*:"
                  "ScoringRealRuns*:KernelContactDamping*")
BUILD_TIMEOUT_S = 3600
TEST_TIMEOUT_S = 1800  # a mutant that makes a test loop counts as noticed
here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))


def read(path):
    with open(path, encoding="utf-8", newline="") as f:
        return f.read()


def write(path, text):
    with open(path, "w", encoding="utf-8", newline="") as f:
        f.write(text)


def usage_error(message):
    print(f"run_mutants.py: {message}", file=sys.stderr)
    return 2


def build(build_dir):
    """True when demcal_tests built."""
    try:
        b = subprocess.run(["cmake", "--build", build_dir, "-j2", "--target", "demcal_tests"],
                           capture_output=True, text=True, timeout=BUILD_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        print("build timed out")
        return False
    if b.returncode:
        print(b.stdout[-2000:] + b.stderr[-2000:])
    return b.returncode == 0


def run_tests(build_dir, flt):
    """(noticed, failed test names)."""
    try:
        r = subprocess.run([os.path.join(build_dir, "demcal_tests"), "--gtest_filter=" + flt,
                            "--gtest_brief=1"], capture_output=True, text=True,
                           timeout=TEST_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        return True, ["(timed out)"]
    failed = sorted({line.split()[3] for line in r.stdout.splitlines()
                     if line.startswith("[  FAILED  ]") and "(" in line})
    return r.returncode != 0, failed


def main():
    args = sys.argv[1:]
    flt = None
    if "--filter" in args:
        k = args.index("--filter")
        if k + 1 >= len(args):
            return usage_error("--filter needs a value")
        flt = args[k + 1]
        del args[k:k + 2]
    if not args:
        print(__doc__, file=sys.stderr)
        return 2
    build_dir = os.path.abspath(args[0])
    listing = args[1] if len(args) > 1 else os.path.join(here, "sphere_kernel.json")
    status = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=root,
                            capture_output=True, text=True)
    if status.returncode:
        return usage_error(f"{root} is not a git checkout (git status failed)")
    if status.stdout.strip():
        return usage_error("the tree has uncommitted changes; run it in a clean clone")
    cache = os.path.join(build_dir, "CMakeCache.txt")
    if not os.path.exists(cache):
        return usage_error(f"{build_dir}: no CMakeCache.txt (configure it with cmake first)")
    home = [line.split("=", 1)[1].strip() for line in read(cache).splitlines()
            if line.startswith("CMAKE_HOME_DIRECTORY:")]
    if not home or os.path.realpath(home[0]) != os.path.realpath(root):
        return usage_error(f"{build_dir} was configured from {home[0] if home else '?'}, "
                           f"not from {root}")
    listed = json.loads(read(listing))
    if isinstance(listed, dict):
        list_filter, mutants = listed.get("filter", DEFAULT_FILTER), listed["mutants"]
    else:
        list_filter, mutants = DEFAULT_FILTER, listed

    # The tests must pass on the tree as it is. The listed files are touched
    # first: a run stopped while its build compiled a mutant leaves an
    # object newer than the restored source, which make would keep.
    for path in sorted({m["file"] for m in mutants}):
        if os.path.exists(os.path.join(root, path)):
            os.utime(os.path.join(root, path))
    if not build(build_dir):
        return usage_error("demcal_tests does not build on the unchanged tree")
    for f in sorted({flt or m.get("filter", list_filter) for m in mutants}):
        failing, names = run_tests(build_dir, f)
        if failing:
            return usage_error(f"the unchanged tree fails {f}: {' '.join(names)}")

    # A mutated file is put back however the run ends (Ctrl-C, kill).
    current = {}

    def restore(*_):
        for path, text in current.items():
            write(path, text)
        sys.exit(130)

    signal.signal(signal.SIGINT, restore)
    signal.signal(signal.SIGTERM, restore)

    counts = {"killed": 0, "SURVIVED": 0, "NOT APPLIED": 0, "BUILD FAILED": 0}
    for m in mutants:
        path = os.path.join(root, m["file"])
        text = read(path)
        if text.count(m["old"]) != 1:
            print(f"{m['name']}: NOT APPLIED ('old' occurs {text.count(m['old'])} times)")
            counts["NOT APPLIED"] += 1
            continue
        t0 = time.time()
        current[path] = text
        try:
            write(path, text.replace(m["old"], m["new"]))
            if not build(build_dir):
                print(f"{m['name']}: BUILD FAILED")
                counts["BUILD FAILED"] += 1
                continue
            noticed, failed = run_tests(build_dir, flt or m.get("filter", list_filter))
        finally:
            write(path, text)
            del current[path]
        verdict = "killed" if noticed else "SURVIVED"
        counts[verdict] += 1
        print(f"{m['name']}: {verdict} ({time.time() - t0:.0f} s) {' '.join(failed)}", flush=True)
    build(build_dir)  # leave the build as the tree is
    print(", ".join(f"{v} {k}" for k, v in counts.items()) + f" of {len(mutants)}")
    return 0 if counts["killed"] == len(mutants) else 1


if __name__ == "__main__":
    sys.exit(main())
