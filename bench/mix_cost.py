#!/usr/bin/env python3
"""What a mixture costs: the S1 column with one material against the same column with three (issue 18 item 1).

The decks (both from bench/make_s1.py's S1 at each N: the same lattice, box, contact law, dt, 2000 untimed +
2000 timed steps):
  one     S1 as it is: one material;
  three   the same particles, each given one of three materials at random (seeded, a third each), so that
          most contacts join two materials: the particle positions come from one state file written here
          (the S1 lattice with its jitter), read by both decks through `initial_state` (v1 for one material,
          v2 with the material column for three). With --same-constants (the default) the three materials
          have S1's constants and every pair S1's coefficients, so the physics is that of `one` and only the
          per-pair work differs (grouping each batch by material pair, one kernel call per run); with
          --different-constants they differ (densities 2500/2650/7800, E 5e6/1e7/2e7, restitution and friction
          per pair), a realistic mix whose dynamics also differ.
Each run is `domel run SCENARIO --quiet --time-after 2000 --threads T` (as run_s1.py); the number is summary.json's
timed_window particle-steps per wall-clock second. Runs alternate one, three, one, three, ... (--reps of each).

Printed: per N x threads the median [min-max] of each, and three/one of the medians (the issue's target: at most
15 % more cost, i.e. three/one >= 1/1.15 = 0.87). CSV: bench/results/mix_cost_<timestamp>.csv.

Usage:
    python3 bench/mix_cost.py --domel build/bin/domel --sizes 10000 50000 --threads 1 2 --reps 5
    python3 bench/mix_cost.py --sizes 2000 --reps 1 --threads 1     # smoke test
Only the Python standard library is used.
"""

import argparse
import csv
import json
import os
import random
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import make_s1  # noqa: E402

MATERIALS_SAME = {m: {"density": make_s1.RHO, "youngs_modulus": make_s1.E, "poisson_ratio": make_s1.NU}
                  for m in ("beads", "glass", "sand")}
MATERIALS_DIFFERENT = {
    "beads": {"density": 2500.0, "youngs_modulus": 5e6, "poisson_ratio": 0.3},
    "glass": {"density": 2650.0, "youngs_modulus": 1e7, "poisson_ratio": 0.25},
    "sand": {"density": 7800.0, "youngs_modulus": 2e7, "poisson_ratio": 0.3},
}


def state_file(path, n, materials, seed):
    """The S1 lattice (make_s1's sites and jitter amplitude, Python's RNG) as a particle state file; with
    materials, v2 with each particle's material drawn at random."""
    nx, ny, nz = make_s1.lattice_dims(n)
    a = make_s1.SPACING * make_s1.D
    rng = random.Random(seed)
    j = make_s1.JITTER * make_s1.D
    lines = ["# S1 lattice for bench/mix_cost.py",
             "id,x,y,z,radius,vx,vy,vz,wx,wy,wz,fixed" + (",material" if materials else "")]
    pick = random.Random(seed + 1)
    k = 0
    for iz in range(nz):
        for iy in range(ny):
            for ix in range(nx):
                k += 1
                p = [(i + 0.5) * a + rng.uniform(-j, j) for i in (ix, iy, iz)]
                row = "%d,%.17g,%.17g,%.17g,%.17g,0,0,0,0,0,0,0" % (k, p[0], p[1], p[2], make_s1.D / 2)
                if materials:
                    row += "," + pick.choice(materials)
                lines.append(row)
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def decks(n, workdir, different):
    base = make_s1.scenario(n)
    base.pop("$schema", None)
    sd = base["subdomains"][0]
    sd.pop("insert")
    one = json.loads(json.dumps(base))
    state_file(os.path.join(workdir, "one_%d.csv" % n), n, None, 7)
    one["subdomains"][0]["initial_state"] = "one_%d.csv" % n
    three = json.loads(json.dumps(base))
    names = ["beads", "glass", "sand"]
    state_file(os.path.join(workdir, "three_%d.csv" % n), n, names, 7)
    three["subdomains"][0]["initial_state"] = "three_%d.csv" % n
    three["materials"] = MATERIALS_DIFFERENT if different else MATERIALS_SAME
    inter = []
    for x in range(3):
        for y in range(x, 3):
            e, mu = (0.5, 0.5) if not different else (0.4 + 0.1 * (x + y), 0.3 + 0.05 * (x + y))
            inter.append({"materials": [names[x], names[y]], "restitution": e, "friction": mu})
    three["interactions"] = inter
    paths = []
    for name, doc in (("one", one), ("three", three)):
        doc["name"] = "mix_%s_%d" % (name, n)
        p = os.path.join(workdir, "%s_%d.json" % (name, n))
        with open(p, "w") as f:
            json.dump(doc, f, indent=1)
        paths.append(p)
    return paths


def run(domel, scenario, threads, workdir, timeout):
    out = tempfile.mkdtemp(dir=workdir)
    env = dict(os.environ, OMP_NUM_THREADS="1")
    env.pop("DOMEL_PLUGIN_PATH", None)
    cmd = [domel, "run", scenario, "--quiet", "--time-after", str(make_s1.NSETTLE), "--threads", str(threads),
           "--out", out]
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout)
    if r.returncode != 0:
        sys.exit("mix_cost.py: %s failed:\n%s" % (" ".join(cmd), r.stderr[-2000:]))
    with open(os.path.join(out, "summary.json")) as f:
        s = json.load(f)
    sd = s["subdomains"][0]
    return s["timed_window"]["particle_steps_per_s"], sd["particles"], sd["final"]["contacts"]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--domel", default=os.path.join(os.path.dirname(HERE), "build", "bin", "domel"))
    ap.add_argument("--sizes", type=int, nargs="+", default=[10000, 50000])
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--timeout", type=float, default=1800)
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--same-constants", dest="different", action="store_false")
    g.add_argument("--different-constants", dest="different", action="store_true")
    ap.set_defaults(different=False)
    args = ap.parse_args(argv)
    workdir = tempfile.mkdtemp(prefix="domel_mix_cost_")
    os.makedirs(os.path.join(HERE, "results"), exist_ok=True)
    stamp = time.strftime("%Y%m%dT%H%M%S")
    csv_path = os.path.join(HERE, "results", "mix_cost_%s.csv" % stamp)
    rows = []
    print("mix_cost.py: %s, %s constants, %d reps, load %.2f" %
          (args.domel, "different" if args.different else "the same", args.reps, os.getloadavg()[0]))
    for n in args.sizes:
        one, three = decks(n, workdir, args.different)
        for t in args.threads:
            got = {"one": [], "three": []}
            for rep in range(args.reps):
                for name, path in (("one", one), ("three", three)):
                    rate, particles, contacts = run(args.domel, path, t, workdir, args.timeout)
                    got[name].append(rate)
                    rows.append({"n": n, "particles": particles, "threads": t, "deck": name, "rep": rep,
                                 "particle_steps_per_s": rate, "final_contacts": contacts,
                                 "constants": "different" if args.different else "same"})
            m1, m3 = statistics.median(got["one"]), statistics.median(got["three"])
            print("N %6d, %d thread(s): one %.3e [%.3e-%.3e], three %.3e [%.3e-%.3e], three/one %.3f (cost +%.1f %%)"
                  % (n, t, m1, min(got["one"]), max(got["one"]), m3, min(got["three"]), max(got["three"]),
                     m3 / m1, 100.0 * (m1 / m3 - 1.0)))
            sys.stdout.flush()
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print("csv:", csv_path)


if __name__ == "__main__":
    main()
