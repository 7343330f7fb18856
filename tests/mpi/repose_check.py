#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The repose heap's angle on MPI ranks against one process (issue 19, item 5; ctest label long).

usage: repose_check.py DOMEL MPIEXEC NPS SCENARIO WORKDIR

SCENARIO is scenarios/ab/collapse_sd_vs_dct.json: a jittered column of about
1900 spheres (sd_critical_angle) collapses on a rough floor into a heap,
at rest by t ~ 0.8 s; the repose probe fits its free surface (output
repose_angle, platform/subdomain/repose_probe.cpp). Run for 1.2 s, VTK off.
NPS is a comma-separated list of rank counts ("2,3,4").

The jitter seed of the column's lattice (insert[1].seed) takes four values.
Each runs on one process and once on ranks, the rank counts taken in turn
(2, 3, 4, 2 ranks for "2,3,4"), so every rank count is tested and the ranks'
heaps come from the same columns as the one process's. Checks:

- every run ran and its summary.json reports an angle; on the ranks the
  final particle count is one process's for the same seed (nothing is
  inserted or removed after the start: no grain is lost or doubled at a
  rank border);
- the angle: the mean of the ranks' four lies within the one-process seeds'
  spread of their mean (|mean_ranks - mean_one| <= max_one - min_one). The
  heap's last grains settle chaotically: round-off (another rank count) moves
  the fitted angle as another column does, so the seed spread is the
  yardstick, as for the silo's discharge (silo_seeds_check.py). Four seeds,
  not three: the difference of two means of n draws has a standard deviation
  of sqrt(2/n) draws' and the expected range of n draws is about 1.7 (n = 3)
  or 2.1 (n = 4) of them, so a heap that behaves on the ranks as on one
  process would fail this check about 1 time in 25 with three seeds and 1 in
  250 with four if the spread took its expected value (normal draws; the
  spread's own scatter makes both somewhat likelier).
"""
import json
import os
import shutil
import sys

import mpi_cli

domel, mpiexec, nps, scenario, work = (sys.argv[1], sys.argv[2], [int(n) for n in sys.argv[3].split(",")],
                                       sys.argv[4], sys.argv[5])
check, failures = mpi_cli.check, mpi_cli.failures

shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
with open(scenario) as f:
    base = json.load(f)
base["output"]["vtk_interval"] = 0
base["run"]["duration"] = 1.2  # at rest by t ~ 0.8 s (tests/validation/collapse_test.cpp)
column = base["subdomains"][0]["insert"][1]
seeds = [column["seed"] + k for k in range(4)]

angles = {"one": [], "ranks": []}
for k, seed in enumerate(seeds):
    np = nps[k % len(nps)]
    counts = {}
    for where, n in (("one", 1), ("ranks", np)):
        doc = json.loads(json.dumps(base))
        doc["subdomains"][0]["insert"][1]["seed"] = seed
        path = os.path.join(work, f"heap_{seed}.json")
        with open(path, "w") as f:
            json.dump(doc, f)
        out = os.path.join(work, f"{where}_{seed}")
        r = mpi_cli.run(mpi_cli.launcher(mpiexec, n) + [domel, "run", path, "--out", out, "--quiet"], 900)
        check(r is not None and r.returncode == 0, f"seed {seed} on {n} rank(s) ran: {r.stderr[-800:] if r else ''}")
        if r is None or r.returncode != 0:
            continue
        s = json.load(open(os.path.join(out, "summary.json")))
        angle = s.get("repose_angle_deg", {}).get("heap")
        check(isinstance(angle, float), f"seed {seed} on {n} rank(s): an angle in summary.json ({angle})")
        if not isinstance(angle, float):
            continue
        angles[where].append(angle)
        counts[where] = s["subdomains"][0]["particles"]
        if n > 1:
            check(counts["ranks"] == counts.get("one"), f"seed {seed} on {n} ranks: the particles of one process: "
                                                        f"{counts}")
        print(f"seed {seed} on {n} rank(s): angle {angle:.2f} deg, {s['wall_time_s']:.1f} s wall", flush=True)

if len(angles["one"]) == len(seeds) and len(angles["ranks"]) == len(seeds):
    m1, mn, spread, within = mpi_cli.mean_within_seed_spread(angles["one"], angles["ranks"])
    print(f"angle of repose, mean of {len(seeds)} columns: one process {m1:.2f} deg (spread {spread:.2f}: "
          f"{', '.join(f'{x:.2f}' for x in angles['one'])}), on {', '.join(str(nps[k % len(nps)]) for k in range(len(seeds)))} ranks {mn:.2f} deg "
          f"({', '.join(f'{x:.2f}' for x in angles['ranks'])}): {mn - m1:+.2f} deg", flush=True)
    check(within, "the ranks' mean angle within the one-process seed spread of its mean")

print("passed" if not failures else f"{len(failures)} failure(s)")
sys.exit(1 if failures else 0)
