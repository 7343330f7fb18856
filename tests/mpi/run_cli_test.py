#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""`mpirun -np N domel run` against `domel run` (ctest label mpi).

usage: run_cli_test.py DOMEL MPIEXEC NP SCENARIO WORKDIR [sanitized]

`sanitized` (scripts/sanitize's build, where the test looks for memory
errors and undefined behaviour on these code paths; the release build's
run checks the numbers): part 8's bed runs 1000 steps (0.02 s: the gas
flow starts and drags the parcels, 200 exchanges) instead of 5000, with
probe rows every 0.002 s, checkpointed at 500 and restarted to 1000; under
the sanitizers its pressure solves took 108 of the test's 203 s.

(The silos' discharge on the ranks: silo_seeds_check.py.)

1. The settle column with a cell grid for 3000 steps (0.03 s: the column
   falls and starts to pile; the runs stay within round-off of each other
   until the pile's collapse turns chaotic, later) on one process and on NP
   ranks: one summary.json, one probes.csv, one particles.pvd series, one
   grid series in the folder; the same particles, steps and probe rows; the
   kinetic energy of every probe row and the grid's layer counts, volume
   fractions, pressures and vertical velocities within 1e-6 relative of
   their largest value (round-off through 3000 steps of collisions:
   measured at most 1e-8 on 2-4 ranks); run again on NP ranks, probes.csv
   and the last particle frame are the same bytes (reproducible for a given
   rank count).
2. A scenario whose levels' rank groups are half given (silo_ci_2lvl with a
   rank_share on its first subdomain only) is refused with the JSON pointer
   of the other, on every rank, non-zero exit, rank 0 alone reporting it,
   nothing written; on 2 ranks, rank groups for silo_3lvl's three levels
   are refused with /subdomains/0/rank_share, nothing written.
3. A failure on rank 0 alone (its output folder holds an earlier run) ends
   every rank with a non-zero exit and that rank's message, never a hang;
   so does a run that blows up (a time step 4 times the stability limit,
   let through by a tiny impact velocity): the rank's message names it.
4. The shaker example (a vibrating box, a binary mixture, region-mass
   probes by material with centres of mass) for 8000 steps: the region
   probes' masses and counts equal one process's in every row, the centres
   of mass within 1e-9 m (round-off; at 0.1 s the vibrated bed has diverged
   by 5e-8 m, as much as one process on 2 threads does from 1 thread).
6. Wall loads (the box, a servo lid pressing on the falling column with
   0.2 N) and contact output for 1000 steps: the wall forces (against the
   largest force component on that wall) and the servo's force and travel
   within 1e-6 of one process's, the lid carrying load by the end, the same
   contact frames with the same number of contacts. The servo feeds the
   chaos of the impacts back into the wall: the ranks' round-off (1e-16 at
   the first contacts) reaches 2e-9 of the lid's force at 1000 steps and
   1e-3 at 3000 (measured on 3 ranks), so the comparison stops at 1000.
7. Checkpoints every 0.005 s: restarted at 1200 steps on NP ranks, the run
   to 2000 writes the uninterrupted run's probes.csv and frames byte for
   byte; restarted on another rank count (NP + 1; one process for NP = 4),
   and from one process's checkpoint on NP ranks, the kinetic energy stays
   within 1e-6 of the uninterrupted run's largest (round-off, as in 1.).
   SIGTERM to every rank (as a batch system sends it) ends the run on every
   rank with a checkpoint, no MPI_Abort, a non-zero status; the run then
   goes on from it.
8. The gas-fluidised bed (scenarios/fluid/bed/a4.json: 619 parcels, the
   vans coupler, drag both ways) for 5000 steps (0.1 s: the bed lifts and
   starts to bubble): the kinetic energy within 1e-6 of one process's
   largest, the net fluid force within 1e-6, the same exchanges and fluid
   frames, one fluid series. Measured on 3 ranks: 2.6e-10 at 0.1 s (the
   bubbling bed is chaotic: at 0.2 s the ranks differ by 8e-3 and one
   process on 2 threads by 2.5e-4 from 1 thread).
9. The column on an STL mesh floor of 32 triangles (the box open at its
   bottom) for 3000 steps: the kinetic energy within 1e-6 of one process's
   largest, the same wall-contact count in every row.
11. A deletion region without a mass-flow plane (the deleting ranks drop
   their ghosts between the probes' gathers): the same particles removed.
10. A pour across the rank borders (random fills into the box every 0.005 s,
   6 g in all) for 6000 steps (the first fills land by 0.03 s): the
   same particles and kg as one process, the same count in every probe row,
   the kinetic energy within 1e-6.
12. Coupled levels (silo_ci_2lvl, its files off) for 1500 steps (0.054 s: the
   coarse pour falls into the fine region, whose first transfers and
   controller actions come at 0.04-0.05 s), on NP ranks twice: every level
   spread over all ranks, and every level on a rank group of its own
   (rank_share): each level's books exact, the same particles in every
   probe row, the same parcels counted and fine particles inserted as one
   process, the kinetic energies within 1e-6 of one process's largest
   (measured 2e-13 at most on 2-4 ranks; one process on 2 threads 8e-17).
   Later the run turns chaotic: the stress controller resets its integral
   where the set point is not positive (physics.md §5.3), and a cell holding
   one free coarse parcel has a kinetic stress of 0 or 1e-35 by round-off, so
   on 3 and 4 ranks (cell sums in another order) a push differs from 0.0575 s
   on (1e-3 by 0.06 s); the fine region's fast collisions do the same from
   0.072 s on 2 ranks and on one process with 2 threads. On rank groups,
   checkpointed at 800 steps: the restart on NP ranks writes the
   uninterrupted run's probes.csv and balance file byte for byte; the
   restart on another rank count is a continuation within 1e-6.
"""
import csv
import json
import os
import re
import shutil
import subprocess
import sys

import mpi_cli

domel, mpiexec, np, scenario, work = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4], sys.argv[5]
sanitized = sys.argv[6:] == ["sanitized"]
mpi = mpi_cli.mpi(mpiexec, np)
env, check, failures = mpi_cli.env, mpi_cli.check, mpi_cli.failures


def run(cmd, timeout=240):
    return mpi_cli.run(cmd, timeout)


def write_scenario(doc, name):
    path = os.path.join(work, name + ".json")
    with open(path, "w") as f:
        json.dump(doc, f)
    return path


def one_and_ranks(path, name, steps):
    """Run `path` for `steps` steps on one process and on the NP ranks; the two folders when both ran, else None."""
    o1, on = os.path.join(work, name + "_one"), os.path.join(work, name + "_ranks")
    r1 = run([domel, "run", path, "--out", o1, "--quiet", "--max-steps", str(steps)])
    rn = run(mpi + [domel, "run", path, "--out", on, "--quiet", "--max-steps", str(steps)])
    ok1, okn = r1 is not None and r1.returncode == 0, rn is not None and rn.returncode == 0
    check(ok1, f"{name} on one process ran: {r1.stderr[-600:] if r1 else ''}")
    check(okn, f"{name} on {np} ranks ran: {rn.stderr[-600:] if rn else ''}")
    return (o1, on) if ok1 and okn else None


def probes(folder):
    with open(os.path.join(folder, "probes.csv")) as f:
        head = f.readline().strip().split(",")
        return head, [[float(x) for x in line.split(",")] for line in f if line.strip()]


shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
mpi_cli.part("1. the settle column")
one, many = os.path.join(work, "one"), os.path.join(work, "ranks")
with open(scenario) as f:
    doc = json.load(f)
doc["output"]["grids"] = [{"name": "bed", "min": [0, 0, 0], "max": [0.02856, 0.02856, 0.06], "cells": [2, 2, 6],
                           "write_interval": 0.005}]
gridded = os.path.join(work, "settle_grid.json")
with open(gridded, "w") as f:
    json.dump(doc, f)
args = ["run", gridded, "--max-steps", "3000", "--quiet"]
r1 = run([domel] + args + ["--out", one])
rn = run(mpi + [domel] + args + ["--out", many])
check(r1 is not None and r1.returncode == 0, "one process ran")
check(rn is not None and rn.returncode == 0, f"{np} ranks ran: {rn.stderr if rn else ''}")
if not failures:
    s1 = json.load(open(os.path.join(one, "summary.json")))
    sn = json.load(open(os.path.join(many, "summary.json")))
    check(sn["ranks"] == np, f"summary.json says {sn['ranks']} ranks")
    check(sn["particles"] == s1["particles"], "the same particles")
    check(sn["steps"] == s1["steps"], "the same steps")
    h1, p1 = probes(one)
    hn, pn = probes(many)
    check(h1 == hn and len(p1) == len(pn), "the same probe columns and rows")
    worst = 0.0
    for a, b in zip(p1, pn):
        check(a[0] == b[0] and a[1] == b[1], f"row at t = {a[0]}: time and particle count")
        for c in (2, 3):  # kinetic energies
            worst = max(worst, abs(a[c] - b[c]) / max(abs(a[c]), 1e-30))
    print(f"{np} ranks: largest relative difference of the kinetic energies over {len(p1)} rows: {worst:.3g}")
    check(worst < 1e-6, f"kinetic energies within 1e-6 (found {worst:.3g})")
    frames = sorted(f for f in os.listdir(many) if re.match(r"particles_\d+\.vtp$", f))
    with open(os.path.join(many, frames[-1]), "rb") as f:
        head = f.read(2000).decode("latin-1")
    check(f'NumberOfPoints="{s1["particles"]}"' in head, "the last frame holds every particle")
    with open(os.path.join(one, "bed_profile.csv")) as f:
        g1 = list(csv.DictReader(f))
    with open(os.path.join(many, "bed_profile.csv")) as f:
        gn = list(csv.DictReader(f))
    check(len(g1) == len(gn) and len(g1) > 6, "the grid's profile rows")
    gworst = 0.0
    for col in ("count", "volume_fraction", "pressure", "vz"):
        scale = max(abs(float(r[col])) for r in g1) or 1.0
        for a, b in zip(g1, gn):
            gworst = max(gworst, abs(float(a[col]) - float(b[col])) / scale)
    print(f"{np} ranks: largest difference of the grid's profile fields, relative to their largest value: {gworst:.3g}")
    check(gworst < 1e-6, f"the grid's fields within 1e-6 (found {gworst:.3g})")
    again = os.path.join(work, "ranks_again")
    ra = run(mpi + [domel] + args + ["--out", again])
    check(ra is not None and ra.returncode == 0, "the second run on the ranks")
    if ra is not None and ra.returncode == 0:
        for name in ("probes.csv", frames[-1], "bed_profile.csv"):
            with open(os.path.join(many, name), "rb") as f1, open(os.path.join(again, name), "rb") as f2:
                check(f1.read() == f2.read(), f"{name} is the same run to run on {np} ranks")
    check(os.listdir(many).count("summary.json") == 1 and not any("rank" in f for f in os.listdir(many)),
          "one set of files")

mpi_cli.part("2. refusals")
# 2. refused on every rank, nothing written
with open(os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(scenario))), "silo",
                       "silo_ci_2lvl.json")) as f:
    doc = json.load(f)
doc["subdomains"][0]["rank_share"] = 1
refused_scenario = os.path.join(work, "half_groups.json")
with open(refused_scenario, "w") as f:
    json.dump(doc, f)
refused_out = os.path.join(work, "refused")
r = run(mpi + [domel, "run", refused_scenario, "--out", refused_out, "--quiet"])
if r is not None:
    check(r.returncode != 0, "half-given rank groups under mpirun are refused")
    check("/subdomains/1" in r.stderr and "rank_share" in r.stderr, "the refusal names the pointer: " + r.stderr)
    check(r.stderr.count("nothing was run") == 1, "rank 0 alone reports it")
    check(not os.path.exists(os.path.join(refused_out, "summary.json")), "nothing written")
# 2b. rank groups for more subdomains than ranks (silo_3lvl's three levels, on 2 ranks): refused, nothing written
if np < 3:
    with open(os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(scenario))), "silo", "silo_3lvl.json")) as f:
        doc = json.load(f)
    for sd in doc["subdomains"]:
        sd["rank_share"] = 1
    few_out = os.path.join(work, "few_ranks")
    r = run(mpi + [domel, "run", write_scenario(doc, "three_groups"), "--out", few_out, "--quiet"])
    if r is not None:
        check(r.returncode != 0, "more rank groups than ranks are refused")
        check("/subdomains/0/rank_share" in r.stderr and "at least 3 ranks" in r.stderr,
              "the refusal names the pointer and the ranks needed: " + r.stderr[-600:])
        check(not os.path.exists(os.path.join(few_out, "summary.json")), "nothing written for the refused groups")

mpi_cli.part("3. failures on a rank")
# 3. rank 0 alone fails (its folder holds the earlier run): every rank ends
r = run(mpi + [domel] + args + ["--out", many], timeout=120)
if r is not None:
    check(r.returncode != 0, "a failure on rank 0 ends the run with a non-zero exit")
    check("earlier run" in r.stderr or "domel_manifest" in r.stderr or "--overwrite" in r.stderr,
          "rank 0's message: " + r.stderr[:400])

# 3b. a run that blows up during the steps
with open(scenario) as f:
    doc = json.load(f)
doc["subdomains"][0]["time_step"] = 6e-4
doc["subdomains"][0]["impact_velocity"] = 1e-4
blow = os.path.join(work, "blow.json")
with open(blow, "w") as f:
    json.dump(doc, f)
r = run(mpi + [domel, "run", blow, "--out", os.path.join(work, "blow"), "--quiet"], timeout=120)
if r is not None:
    check(r.returncode == 1, f"a blown-up run ends with exit status 1 (found {r.returncode})")
    check("failed on rank" in r.stderr and "non-finite" in r.stderr, "the rank's message: " + r.stderr[:400])

mpi_cli.part("4. the shaker")
# 4. the shaker: moving walls, materials, region-mass probes
shaker = os.path.join(os.path.dirname(os.path.abspath(scenario)), "shaker.json")
folders = one_and_ranks(shaker, "shaker", 8000)
if folders:
    o1, on = folders
    h1, p1 = probes(o1)
    hn, pn = probes(on)
    check(h1 == hn and len(p1) == len(pn) and len(p1) > 3, "the shaker's probe columns and rows")
    region = [c for c, name in enumerate(h1) if name.endswith((".mass_kg", ".particles"))]
    com = [c for c, name in enumerate(h1) if ".com_" in name]
    check(len(region) >= 4 and len(com) >= 6, "the shaker has region-mass probes with centres of mass")
    for a, b in zip(p1, pn):
        for c in region:
            check(abs(a[c] - b[c]) <= 1e-12 * abs(a[c]), f"{h1[c]} at t = {a[0]}: {a[c]} against {b[c]}")
        for c in com:
            check(abs(a[c] - b[c]) <= 1e-9, f"{h1[c]} at t = {a[0]}: {a[c]} against {b[c]}")

mpi_cli.part("6. wall loads and a servo")
# 6. wall loads, contact output and a servo lid pressing on the column
with open(scenario) as f:
    doc = json.load(f)
doc["walls"].append({"name": "lid", "type": "plane", "material": "beads", "point": [0, 0, 0.0572],
                     "normal": [0, 0, -1],
                     "motion": {"servo": {"direction": [0, 0, -1], "force": 0.2, "max_velocity": 0.2}}})
doc["output"]["wall_loads"] = [{"wall": "box"}, {"wall": "lid"}]
doc["output"]["contacts"] = {"interval": 0.0025}
folders = one_and_ranks(write_scenario(doc, "loads"), "loads", 1000)
if folders:
    o1, on = folders
    h1, p1 = probes(o1)
    hn, pn = probes(on)
    check(h1 == hn and len(p1) == len(pn), "the same probe columns and rows")
    loads = [c for c, name in enumerate(h1) if ".force_" in name or ".servo_" in name]
    check(len(loads) == 8, f"box and lid loads, the servo's force and travel: {[h1[c] for c in loads]}")
    worst = 0.0
    for c in loads:
        # a force component against the largest component on its wall
        same = [d for d in loads if h1[d].split(".")[0] == h1[c].split(".")[0] and ".force_" in h1[d]]
        scale = max(abs(row[d]) for row in p1 for d in (same if ".force_" in h1[c] else [c]) if row[d] == row[d]) or 1.0
        for a, b in zip(p1, pn):
            if a[c] != a[c] or b[c] != b[c]:
                check((a[c] != a[c]) == (b[c] != b[c]), f"{h1[c]} at t = {a[0]}: {a[c]} against {b[c]}")
                continue
            worst = max(worst, abs(a[c] - b[c]) / scale)
    lid_force = h1.index("lid.servo_force")
    print(f"{np} ranks: wall loads and servo within {worst:.3g} of one process, relative to their largest value; "
          f"lid force at the end {p1[-1][lid_force]:.4g} N (one process) {pn[-1][lid_force]:.4g} N")
    check(worst < 1e-6, f"wall loads and servo within 1e-6 (found {worst:.3g})")
    check(p1[-1][lid_force] > 0.01, "the lid carries load by the end (the test exercises the servo)")
    f1 = sorted(f for f in os.listdir(o1) if re.match(r"contacts_\d+\.vtp$", f))
    fn = sorted(f for f in os.listdir(on) if re.match(r"contacts_\d+\.vtp$", f))
    check(f1 == fn and len(f1) >= 3, f"the same contact frames: {f1} against {fn}")
    for name in f1[1:] if f1 == fn else []:
        counts = []
        for folder in (o1, on):
            with open(os.path.join(folder, name), "rb") as f:
                m = re.search(r'NumberOfLines="(\d+)"', f.read(4000).decode("latin-1"))
            counts.append(int(m.group(1)) if m else -1)
        check(counts[0] == counts[1] and counts[0] > 100, f"{name}: {counts[0]} contacts on one process, {counts[1]} on the ranks")

mpi_cli.part("7. checkpoints")
# 7. checkpoints: a restart on the same rank count goes on bit for bit; on
# another rank count (and from one process's checkpoint) it is a valid
# continuation; SIGTERM to the ranks ends every one with a checkpoint
with open(scenario) as f:
    doc = json.load(f)
doc["run"]["checkpoint_interval"] = 0.005
doc["output"]["vtk_interval"] = 0.005
ck_scenario = os.path.join(work, "ck.json")
with open(ck_scenario, "w") as f:
    json.dump(doc, f)
ck_full, ck_part = os.path.join(work, "ck_full"), os.path.join(work, "ck_part")
other = 1 if np == 4 else np + 1
ck_other, ck_from_one = os.path.join(work, "ck_other"), os.path.join(work, "ck_from_one")
runs = [run(mpi + [domel, "run", ck_scenario, "--out", ck_full, "--quiet", "--max-steps", "2000"]),
        run(mpi + [domel, "run", ck_scenario, "--out", ck_part, "--quiet", "--max-steps", "1200"]),
        run([domel, "run", ck_scenario, "--out", ck_from_one, "--quiet", "--max-steps", "1200"])]
check(all(r is not None and r.returncode == 0 for r in runs), "the checkpointed runs ran")
if not failures or all(r is not None and r.returncode == 0 for r in runs):
    shutil.copytree(ck_part, ck_other)
    restart = ["--quiet", "--max-steps", "2000", "--restart"]
    r_same = run(mpi + [domel, "run", ck_scenario, "--out", ck_part] + restart + [os.path.join(ck_part, "checkpoint.ckpt")])
    r_other = run(([mpiexec, "-np", str(other), "--oversubscribe"] if other > 1 else []) +
                  [domel, "run", ck_scenario, "--out", ck_other] + restart + [os.path.join(ck_other, "checkpoint.ckpt")])
    r_one = run(mpi + [domel, "run", ck_scenario, "--out", ck_from_one] + restart +
                [os.path.join(ck_from_one, "checkpoint.ckpt")])
    for r, what in ((r_same, f"on {np} ranks"), (r_other, f"on {other} rank(s)"), (r_one, "of one process on the ranks")):
        check(r is not None and r.returncode == 0, f"the restart {what} ran: {r.stderr if r else ''}")
    if all(r is not None and r.returncode == 0 for r in (r_same, r_other, r_one)):
        same = [f for f in os.listdir(ck_full) if f == "probes.csv" or f.endswith(".vtp")]
        check(len(same) >= 5, f"files to compare: {same}")
        for name in same:
            with open(os.path.join(ck_full, name), "rb") as f1, open(os.path.join(ck_part, name), "rb") as f2:
                check(f1.read() == f2.read(), f"{name}: the restart on {np} ranks writes the uninterrupted run's bytes")
        check(r_other.stderr.count("shared out anew") == 1, "the other rank count's restart says it is a continuation")
        h0, p0 = probes(ck_full)
        ke = h0.index("column.ke_translational")
        scale = max(row[ke] for row in p0)
        for folder, what in ((ck_other, f"{other} rank(s)"), (ck_from_one, "one process's checkpoint")):
            h, pr = probes(folder)
            check(h == h0 and len(pr) == len(p0), f"the restart on {what}: the same probe rows")
            worst = max(abs(a[ke] - b[ke]) / scale for a, b in zip(p0, pr))
            print(f"restart on {what} from the checkpoint at 1200 steps: kinetic energy within {worst:.3g} of "
                  f"the uninterrupted {np}-rank run's largest")
            check(worst < 1e-6, f"the restart on {what}: kinetic energy within 1e-6 (found {worst:.3g})")
    # SIGTERM to every rank (as a batch system sends it)
    doc["run"]["duration"] = 5.0
    long_scenario = os.path.join(work, "ck_long.json")
    with open(long_scenario, "w") as f:
        json.dump(doc, f)
    ck_sig = os.path.join(work, "ck_signal")
    proc = subprocess.Popen(mpi + [domel, "run", long_scenario, "--out", ck_sig, "--quiet"], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    import time
    deadline = time.time() + 60
    while time.time() < deadline and not os.path.exists(os.path.join(ck_sig, "particles_000002.vtp")):
        time.sleep(0.2)
    subprocess.run(["pkill", "-TERM", "-f", f"domel run {long_scenario} --out {ck_sig}"])
    try:
        out, err = proc.communicate(timeout=60)
        check(proc.returncode != 0, "a run stopped by SIGTERM ends with a non-zero status")
        summary = json.load(open(os.path.join(ck_sig, "summary.json")))
        check(summary["status"] == "interrupted" and summary.get("checkpoint") == "checkpoint.ckpt",
              f"summary.json: interrupted, with its checkpoint: {summary.get('status')}")
        check(err.count("interrupted at t =") == 1 and "MPI_ABORT" not in err,
              "every rank ended cleanly, rank 0 said where: " + err[-400:])
        r = run(mpi + [domel, "run", long_scenario, "--out", ck_sig, "--quiet", "--max-steps",
                       str(summary["steps"] + 100), "--restart", os.path.join(ck_sig, "checkpoint.ckpt")])
        check(r is not None and r.returncode == 0, "the interrupted run goes on from its checkpoint")
    except subprocess.TimeoutExpired:
        proc.kill()
        check(False, "SIGTERM to the ranks: a hang")

mpi_cli.part("8. the fluidised bed")
# 8. the fluid coupling: a gas-fluidised bed (scenarios/fluid/bed/a4.json, 619 parcels, the vans coupler)
bed = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(scenario))), "fluid", "bed", "a4.json")
bed_steps, bed_rows, bed_ck = (1000, 0.002, 0.01) if sanitized else (5000, 0.01, 0.02)
with open(bed) as f:
    doc = json.load(f)
doc["output"]["probe_interval"] = bed_rows
bed = write_scenario(doc, "bed")  # a4.json names no other file
folders = one_and_ranks(bed, "bed", bed_steps)
if folders:
    f1, fn = folders
    h1, p1 = probes(f1)
    hn, pn = probes(fn)
    check(h1 == hn and len(p1) == len(pn) and len(p1) >= 10, "the bed's probe rows")
    ke = h1.index("beads.ke_translational")
    scale = max(row[ke] for row in p1)
    worst = max(abs(a[ke] - b[ke]) / scale for a, b in zip(p1, pn))
    a, b = (json.load(open(os.path.join(d, "summary.json")))["fluid"] for d in (f1, fn))
    fa, fb = a["levels"][0]["net_fluid_force_N"][2], b["levels"][0]["net_fluid_force_N"][2]
    print(f"fluidised bed on {np} ranks: kinetic energy within {worst:.3g} of one process's largest, net fluid "
          f"force {fb:.9g} N against {fa:.9g} N; coupler {b['coupler_seconds_per_exchange'] * 1e3:.3g} ms per "
          f"exchange against {a['coupler_seconds_per_exchange'] * 1e3:.3g} ms")
    check(worst < 1e-6, f"the bed's kinetic energy within 1e-6 (found {worst:.3g})")
    check(abs(fa - fb) <= 1e-6 * abs(fa), f"the net fluid force within 1e-6: {fa} against {fb}")
    check(a["exchanges"] == b["exchanges"] and b.get("fields") == "fluid.pvd", "the same exchanges, one fluid series")
    frames1 = sorted(f for f in os.listdir(f1) if f.startswith("fluid_"))
    check(frames1 == sorted(f for f in os.listdir(fn) if f.startswith("fluid_")) and len(frames1) >= 1,
          "the same fluid frames")
    # checkpointed on NP ranks (at 1000 steps; sanitized 500), restarted on another rank count (the coupler's per-particle
    # arrays travel with the particles shared out anew)
    with open(bed) as f:
        doc = json.load(f)
    doc["run"]["checkpoint_interval"] = bed_ck
    bed_ck_file = write_scenario(doc, "bed_ck")
    fc = os.path.join(work, "bed_ck")
    ck_steps = round(bed_ck / doc["subdomains"][0]["time_step"])
    r = run(mpi + [domel, "run", bed_ck_file, "--out", fc, "--quiet", "--max-steps", str(ck_steps)])
    check(r is not None and r.returncode == 0, "the checkpointed bed ran")
    r = run(([mpiexec, "-np", str(other), "--oversubscribe"] if other > 1 else []) +
            [domel, "run", bed_ck_file, "--out", fc, "--quiet", "--max-steps", str(2 * ck_steps), "--restart",
             os.path.join(fc, "checkpoint.ckpt")])
    check(r is not None and r.returncode == 0, f"the bed restarted on {other} rank(s): {r.stderr if r else ''}")
    if r is not None and r.returncode == 0:
        hc, pc = probes(fc)
        worst = max(abs(x[ke] - y[ke]) / scale for x, y in zip(pn, pc))
        check(len(pc) >= 4 and worst < 1e-6, f"the restarted bed within 1e-6 of the uninterrupted run (found {worst:.3g})")

mpi_cli.part("9. a mesh floor")
# 9. a mesh wall across the ranks: the column settles on an STL floor of 32 triangles
with open(scenario) as f:
    doc = json.load(f)
side, cells = 0.02856, 4
with open(os.path.join(work, "floor.stl"), "w") as f:
    f.write("solid floor\n")
    for i in range(cells):
        for j in range(cells):
            x0, x1, y0, y1 = i * side / cells, (i + 1) * side / cells, j * side / cells, (j + 1) * side / cells
            for t in (((x0, y0), (x1, y0), (x1, y1)), ((x0, y0), (x1, y1), (x0, y1))):
                f.write(" facet normal 0 0 1\n  outer loop\n")
                for x, y in t:
                    f.write(f"   vertex {x!r} {y!r} 0\n")
                f.write("  endloop\n endfacet\n")
    f.write("endsolid floor\n")
doc["walls"][0]["open"] = ["zmin", "zmax"]
doc["walls"].append({"name": "floor", "type": "mesh", "material": "beads", "file": "floor.stl"})
folders = one_and_ranks(write_scenario(doc, "mesh_floor"), "mesh", 3000)  # floor.stl beside it
if folders:
    m1, mn = folders
    h1, p1 = probes(m1)
    hn, pn = probes(mn)
    ke, wc = h1.index("column.ke_translational"), h1.index("column.wall_contacts")
    scale = max(row[ke] for row in p1)
    worst = max(abs(a[ke] - b[ke]) / scale for a, b in zip(p1, pn))
    print(f"mesh floor on {np} ranks: kinetic energy within {worst:.3g} of one process's largest; wall contacts "
          f"at the end {p1[-1][wc]:.0f} (one process) {pn[-1][wc]:.0f}")
    check(h1 == hn and len(p1) == len(pn), "the mesh floor's probe rows")
    check(worst < 1e-6, f"the mesh floor: kinetic energy within 1e-6 (found {worst:.3g})")
    check(all(a[wc] == b[wc] for a, b in zip(p1, pn)) and p1[-1][wc] > 100,
          "the same wall contacts in every row, more than 100 at the end (the floor carries the column)")

mpi_cli.part("11. a deletion region")
# 11. a deletion region without a mass-flow plane: the ranks that delete drop their ghosts before the
# probes' gather (the ghosts' contact counts must have gone home first)
with open(scenario) as f:
    doc = json.load(f)
doc["deletion_regions"] = [{"name": "low", "region": {"box": {"min": [0, 0, 0], "max": [0.02856, 0.02856, 0.01]}}}]
doc["run"]["deletion_interval"] = 0.001
doc["output"]["probe_interval"] = 0.0005
folders = one_and_ranks(write_scenario(doc, "deletion"), "deletion", 2000)
if folders:
    d1, dn = folders
    a, b = (json.load(open(os.path.join(d, "summary.json"))) for d in (d1, dn))
    check(a["deletion_regions"]["low"]["removed"] == b["deletion_regions"]["low"]["removed"] > 0 and
          a["particles"] == b["particles"], f"the same particles removed: {a['deletion_regions']} {b['deletion_regions']}")

mpi_cli.part("10. a pour")
# 10. a pour across the rank borders: random fills into the box every 0.005 s
with open(scenario) as f:
    doc = json.load(f)
sd = doc["subdomains"][0]
sd.pop("insert")
sd["pour"] = [{"insert": {"model": "random", "diameter": 0.0028, "volume_fraction": 0.05,
                          "region": {"box": {"min": [0, 0, 0.005], "max": [0.02856, 0.02856, 0.035]}}},
                "mass_rate": 0.2, "total_mass": 0.006, "interval": 0.005}]
folders = one_and_ranks(write_scenario(doc, "pour"), "pour", 6000)
if folders:
    q1, qn = folders
    a, b = (json.load(open(os.path.join(d, "summary.json"))) for d in (q1, qn))
    pa, pb = a["pours"][0], b["pours"][0]
    check(pa["inserted"] == pb["inserted"] and pa["inserted"] > 100 and pa["inserted_kg"] == pb["inserted_kg"],
          f"the pour inserts what one process inserts: {pa['inserted']} ({pa['inserted_kg']} kg) against "
          f"{pb['inserted']} ({pb['inserted_kg']} kg)")
    h1, p1 = probes(q1)
    hn, pn = probes(qn)
    ke = h1.index("column.ke_translational")
    scale = max(row[ke] for row in p1)
    worst = max(abs(x[ke] - y[ke]) / scale for x, y in zip(p1, pn))
    check(all(x[1] == y[1] for x, y in zip(p1, pn)), "the same particle count in every probe row")
    print(f"pour on {np} ranks: {pb['inserted']} particles in {pb['events']} events as on one process; kinetic "
          f"energy within {worst:.3g} of one process's largest")
    check(worst < 1e-6, f"the pour: kinetic energy within 1e-6 (found {worst:.3g})")

mpi_cli.part("12. coupled levels")
# 12. coupled levels: spread over all ranks, and on rank groups; restarts on rank groups
with open(os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(scenario))), "silo",
                       "silo_ci_2lvl.json")) as f:
    doc = json.load(f)
doc["output"]["vtk_interval"] = 0
doc["output"].pop("grids", None)
doc["couplings"][0]["grid_interval"] = 0
levels = write_scenario(doc, "levels")
o1 = os.path.join(work, "levels_one")
r1 = run([domel, "run", levels, "--out", o1, "--quiet", "--max-steps", "1500"])
check(r1 is not None and r1.returncode == 0, f"the coupled levels on one process ran: {r1.stderr[-600:] if r1 else ''}")
for sd in doc["subdomains"]:
    sd["rank_share"] = 1
doc["run"]["checkpoint_interval"] = 0.02
grouped = write_scenario(doc, "levels_groups")
folders = {}
for mode, path in (("spread", levels), ("groups", grouped)):
    folders[mode] = os.path.join(work, "levels_" + mode)
    r = run(mpi + [domel, "run", path, "--out", folders[mode], "--quiet", "--max-steps", "1500"])
    check(r is not None and r.returncode == 0, f"the coupled levels on {np} ranks ({mode}) ran: {r.stderr[-600:] if r else ''}")
if r1 is not None and r1.returncode == 0 and all(os.path.exists(os.path.join(f, "summary.json")) for f in folders.values()):
    a = json.load(open(os.path.join(o1, "summary.json")))
    h1, p1 = probes(o1)
    ke = [c for c, name in enumerate(h1) if ".ke_" in name]
    counts = [c for c, name in enumerate(h1) if name.endswith(".particles")]
    for mode, folder in folders.items():
        b = json.load(open(os.path.join(folder, "summary.json")))
        for level in ("alpha2", "alpha1"):
            bal = b["mass_balance"][level]
            check(bal["exact"] and bal["residual_units_1e-18kg"] == 0, f"{mode}: {level}'s books exact: {bal}")
        fa, fb = a["couplings"]["zone1"]["faces"]["+z"], b["couplings"]["zone1"]["faces"]["+z"]
        check(fa["counted_parcels"] == fb["counted_parcels"] > 0 and fa["inserted"] == fb["inserted"] > 500,
              f"{mode}: the parcels counted and the fine particles inserted as on one process: {fa} against {fb}")
        if mode == "groups":
            groups = sorted((g["rank_group"]["first"], g["rank_group"]["count"]) for g in b["subdomains"])
            check(groups[0][0] == 0 and groups[0][0] + groups[0][1] == groups[1][0] and sum(g[1] for g in groups) == np,
                  f"disjoint rank groups covering the {np} ranks: {groups}")
        hn, pn = probes(folder)
        check(h1 == hn and len(p1) == len(pn) and len(p1) >= 6, f"{mode}: the same probe rows")
        worst = 0.0
        for c in ke:
            scale = max(abs(row[c]) for row in p1) or 1.0
            worst = max([worst] + [abs(x[c] - y[c]) / scale for x, y in zip(p1, pn)])
        check(all(x[c] == y[c] for x, y in zip(p1, pn) for c in counts), f"{mode}: the same particles in every row")
        print(f"coupled levels on {np} ranks ({mode}): kinetic energies within {worst:.3g} of one process's largest; "
              f"{fb['counted_parcels']} parcels counted, {fb['inserted']} fine particles inserted")
        check(worst < 1e-6, f"{mode}: the kinetic energies within 1e-6 (found {worst:.3g})")
    # restarts on rank groups
    part, moved = os.path.join(work, "levels_part"), os.path.join(work, "levels_moved")
    r = run(mpi + [domel, "run", grouped, "--out", part, "--quiet", "--max-steps", "800"])
    check(r is not None and r.returncode == 0, "the checkpointed coupled levels ran")
    if r is not None and r.returncode == 0:
        shutil.copytree(part, moved)
        restart = ["--quiet", "--max-steps", "1500", "--restart"]
        r = run(mpi + [domel, "run", grouped, "--out", part] + restart + [os.path.join(part, "checkpoint.ckpt")])
        check(r is not None and r.returncode == 0, f"the restart on {np} ranks ran: {r.stderr[-600:] if r else ''}")
        if r is not None and r.returncode == 0:
            for name in ("probes.csv", "zone1_balance.csv"):
                with open(os.path.join(folders["groups"], name), "rb") as f1, open(os.path.join(part, name), "rb") as f2:
                    check(f1.read() == f2.read(), f"{name}: the restart on rank groups writes the uninterrupted run's bytes")
        r = run(([mpiexec, "-np", str(other), "--oversubscribe"] if other > 1 else []) +
                [domel, "run", grouped, "--out", moved] + restart +
                [os.path.join(moved, "checkpoint.ckpt")])
        check(r is not None and r.returncode == 0, f"the restart on {other} ranks ran: {r.stderr[-600:] if r else ''}")
        if r is not None and r.returncode == 0:
            hg, pg = probes(folders["groups"])
            hm, pm = probes(moved)
            worst = max(abs(x[c] - y[c]) / (max(abs(row[c]) for row in pg) or 1.0) for x, y in zip(pg, pm) for c in ke)
            check(hg == hm and len(pg) == len(pm), "the restart on another rank count: the same probe rows")
            check(worst < 1e-6, f"the restart on {other} ranks: kinetic energies within 1e-6 (found {worst:.3g})")

mpi_cli.part(None)
print("passed" if not failures else f"{len(failures)} failure(s)")
sys.exit(1 if failures else 0)
