#!/usr/bin/env python3
"""The 3D tolerance atlas (reports/atlas-3d.md): criteria against peak error.

Runs `demcal run` on a 3D config around a calibrated point (params.json of
`demcal calibrate`), varying alpha, zeta_t, zeta_r and Nstep, and scores each
run's step-level axial peak against the converged one: Richardson from the
calibrated multipliers at 8x and 16x Nstep, 2 P(16N) - P(8N). Also reads the
calibration's own trials.jsonl (finished trials) as more points.

  reports/atlas-3d/atlas3d.py DEMCAL CONFIG PARAMS_DIR OUT_JSONL [--jobs 2] [--trials-only]

--trials-only: no sweep; the calibration's finished trials only, against the
Richardson limit of its certificate pair, 2 P(2N) - P(N) (for a scene whose
runs are too long to sweep).
"""
import json, os, subprocess, sys, tempfile
from concurrent.futures import ThreadPoolExecutor

demcal, config, pdir, out = sys.argv[1:5]
jobs = int(sys.argv[sys.argv.index("--jobs") + 1]) if "--jobs" in sys.argv else 2
params = json.load(open(os.path.join(pdir, "params.json")))
rev = params["rev"]
a0, zt0, zr0, n0 = rev["dt_ratio"], rev["damping_ratio_translation"], rev["damping_ratio_rotation"], rev["steps"]
stable = params["dt_ratio_stable"]
work = tempfile.mkdtemp(prefix="atlas3d-")


def run(a, zt, zr, n):
    d = os.path.join(work, f"a{a:.4f}_zt{zt:.4f}_zr{zr:.4f}_n{n}")
    args = [demcal, "run", config, "-o", d, "--allow-unstable",
            "--set", f"algorithm.dt_ratio={a}", "--set", f"algorithm.steps={n}",
            "--set", f"algorithm.damping_ratio_translation={zt}",
            "--set", f"algorithm.damping_ratio_rotation={zr}", "--set", "output.vtk=false"]
    p = subprocess.run(args, capture_output=True, text=True)
    # demcal run exits 0 on PASS, 1 on FAIL or DIVERGED (files written
    # either way), 2 on bad input: only the last is an error here.
    if p.returncode not in (0, 1):
        return {"params": [a, zt, zr, n], "error": p.stderr.strip()[-300:]}
    s = json.load(open(os.path.join(d, "summary.json")))
    # The planes' combination as measured (summary.json's "criteria" have the
    # drag folded into moment balance; table.py judges the drag on its own).
    planes = s["criteria_planes"]
    crit = dict(planes.get("combined_without_drag", s["criteria"]))
    for k in ("rotational_drag", "translational_drag"):
        crit[k] = planes.get(k)
    return {"params": [a, zt, zr, n], "criteria": crit,
            "peak": s["peak"]["stress_zz"], "diverged": s["diverged"],
            "steps_run": s["steps_run"], "wall_time_s": s["wall_time_s"]}


trials_only = "--trials-only" in sys.argv
pts = [(a0, zt0, zr0, 8 * n0), (a0, zt0, zr0, 16 * n0)]
# One at a time around the calibrated point, and Nstep against each.
for f in (0.25, 0.5, 1, 2, 4):
    pts.append((a0, zt0, zr0, int(round(n0 * f))))
for a in (0.05, 0.1, 0.2, 0.3, 0.95 * stable):
    for f in (0.5, 1, 2):
        pts.append((round(a, 4), zt0, zr0, int(round(n0 * f))))
for zt in (0.1, 0.25, 1.0, 2.0, 4.0):
    for f in (0.5, 1, 2):
        pts.append((a0, zt, zr0, int(round(n0 * f))))
for zr in (0.0, 0.1, 0.5, 1.0, 2.0):
    for f in (0.5, 1, 2):
        pts.append((a0, zt0, zr, int(round(n0 * f))))
pts = list(dict.fromkeys(pts))
if trials_only:
    c = params["certificate"]
    results = []
    p_a, p_b, law = c["peak_stress_yy"], c["peak_stress_yy_steps_doubled"], "2 P(2N) - P(N)"
else:
    with ThreadPoolExecutor(jobs) as ex:
        results = list(ex.map(lambda p: run(*p), pts))
    p_a, p_b, law = results[0]["peak"], results[1]["peak"], "2 P(16N) - P(8N)"
ref = 2 * p_b - p_a
with open(out, "w") as f:
    f.write(json.dumps({"reference_peak": ref, "p_coarse": p_a, "p_fine": p_b, "law": law,
                        "calibrated": [a0, zt0, zr0, n0], "dt_ratio_stable": stable}) + "\n")
    for r in results:
        r["source"] = "sweep"
        f.write(json.dumps(r) + "\n")
    tj = os.path.join(pdir, "trials.jsonl")
    for line in open(tj):
        t = json.loads(line)
        if not t["complete"]:
            continue
        p = t["params"]
        f.write(json.dumps({"params": [p["dt_ratio"], p["damping_ratio_translation"],
                                       p["damping_ratio_rotation"], p["steps"]],
                            "criteria": t["criteria"], "peak": t["peak_stress_yy"],
                            "diverged": t["diverged"], "steps_run": t["steps_run"],
                            "source": "calibration " + t["phase"]}) + "\n")
print(out, "reference", ref)
