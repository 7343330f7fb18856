#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The 10k settle (scenarios/validation/settle_10k.json) under `mpirun -np N` (ctest label mpi).

usage: settle_10k_check.py DOMEL MPIEXEC NP SCENARIO WORKDIR

The acceptance of tests/validation/settle_test.cpp (the same column on one
process), read from the outputs of the run spread over NP ranks: every one
of the 10 115 particles still inside the box at the end (a region-mass probe
over the box's inside counts them: x and y within the walls, z above the
floor), the largest overlap below 1 % of the diameter at rest (the largest
static Hertz overlap of this material is ~0.5 % d), and the kinetic energy
decayed below 1e-4 of its peak (probes every 2 ms; one process reaches
~1e-7). Every rank runs its share; the run takes about a minute on 2 cores.
"""
import csv
import json
import os
import shutil
import subprocess
import sys

import mpi_cli

domel, mpiexec, np, scenario, work = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4], sys.argv[5]
env = mpi_cli.env
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
with open(scenario) as f:
    doc = json.load(f)
a = 1.02 * 0.0028
inside = {"box": {"min": [0, 0, 0], "max": [17 * a, 17 * a, 1.0]}}  # the box's walls, open top
doc["output"]["region_mass"] = [{"name": "inside", "region": inside}]
doc["output"]["vtk_interval"] = 0
path = os.path.join(work, "settle_10k.json")
with open(path, "w") as f:
    json.dump(doc, f)
out = os.path.join(work, "out")
r = subprocess.run([mpiexec, "-np", str(np), "--oversubscribe", domel, "run", path, "--out", out, "--quiet"],
                   env=env, capture_output=True, text=True, timeout=900)
if r.returncode != 0:
    print(r.stdout, r.stderr)
    sys.exit(f"mpirun -np {np} domel run settle_10k.json exited with {r.returncode}")
s = json.load(open(os.path.join(out, "summary.json")))
rows = list(csv.DictReader(open(os.path.join(out, "probes.csv"))))
last = rows[-1]
ke = lambda row: float(row["column.ke_translational"]) + float(row["column.ke_rotational"])
peak = max(ke(row) for row in rows)
failures = []
if s["ranks"] != np:
    failures.append(f"summary.json says {s['ranks']} ranks")
if s["particles"] != 10115:
    failures.append(f"{s['particles']} particles at the end, expected 10115")
if int(float(last["inside.particles"])) != 10115:
    failures.append(f"{last['inside.particles']} particles inside the box at the end, expected 10115")
overlap = float(last["column.max_overlap_ratio"])
if not overlap < 0.01:
    failures.append(f"largest overlap {overlap:.4f} d at rest, expected below 0.01 d")
if not (peak > 0 and ke(last) < 1e-4 * peak):
    failures.append(f"kinetic energy {ke(last):.3g} J at the end against a peak of {peak:.3g} J: not below 1e-4")
print(f"settle_10k on {np} ranks: {s['particles']} particles, {last['inside.particles']} inside the box, "
      f"{last['column.contacts']} contacts, max overlap {overlap:.4f} d, KE end/peak {ke(last) / peak:.3g}")
for f in failures:
    print("FAIL:", f)
sys.exit(1 if failures else 0)
