#!/usr/bin/env python3
"""Prepare the dense settled-bed benchmark (issue 5): one bed of N spheres, the same for domel and LIGGGHTS.

S1 and S2 measure a column that is still compacting: at the timed steps it holds 1-2 contacts per particle, so
the contact kernels are a small part of the work. A settled bed holds 5-6 (issue 5 asks for a mean of at least
5), which is what a silo, a heap or a mixer spends most of its time in. This script makes such a bed once and
writes it for both codes, so that both start from exactly the same positions:

1. Preparation (domel, untimed, cached): N spheres of the S1 material (d = 2.8 mm, rho = 2500, E = 5e6 Pa,
   nu = 0.3) are placed at random (random sequential addition, volume fraction 0.2) in a box of S1's footprint
   (nx * 1.02 d square, nx = round((N/2)^(1/3)), open at the top) and fall under gravity. The preparation is
   frictionless with restitution 0.1: without friction the spheres slide into a dense random packing (about 6
   contacts per sphere, where frictional deposition stops near 4-5), and the low restitution makes it come to
   rest quickly. Simulated time: the free-fall time of the fill height plus 0.15 s.
2. The bed: the prepared positions and radii, with every velocity set to zero, written as
     bed_<label>.csv   domel particle state (subdomains[0].initial_state),
     bed_<label>.data  LIGGGHTS data file (atom_style granular: id type diameter density x y z),
     bed_<label>.meta.json  the preparation's parameters (the cache key) and the bed's facts,
   and, written by scenario_file(), bed_<label>[_<rolling>].json, the domel benchmark scenario: S1's contact model and deck (Hertz + restitution 0.5 +
                       Mindlin mu = 0.5, dt = 1e-5 s, skin 0.5 d, gravity, a box open at the top), NSETTLE
                       untimed + NRUN timed steps,
   and bench/liggghts/bed.in is the LIGGGHTS deck that reads bed_<label>.data with the peers' contact model
   files (../shared/peers/liggghts/model_<RF>.in).
Switching friction on turns the frictionless packing into a frictional one at rest; the untimed steps let the
tangential springs load under gravity before the timed steps.

Usage:
    python3 bench/make_bed.py --sizes 10000 50000 --workdir bench/work --domel build-bench/bin/domel
Prints, per N, the bed's height, solid fraction, contacts per particle and kinetic energy at the end of the
preparation. Reuses a prepared bed when its bed_<label>.meta.json carries the same parameters (`prep` key).
"""

import argparse
import json
import math
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import make_s1  # noqa: E402  (same folder: the S1 material, deck constants, JSON layout)

D, RHO, E, NU, REST, MU, DT, SKIN = (make_s1.D, make_s1.RHO, make_s1.E, make_s1.NU, make_s1.REST, make_s1.MU,
                                     make_s1.DT, make_s1.SKIN)
FILL_FRACTION = 0.2     # random sequential addition: bounded regions jam well below its bulk limit of 0.38
PREP_RESTITUTION = 0.1  # preparation only: settles fast
PREP_EXTRA_S = 0.15     # preparation time after the free fall of the fill height [s]
PREP_SEED = 2718281
NSETTLE = 500           # untimed steps of the benchmark (friction loads)
NRUN = 2000             # timed steps
VERSION = 1             # bump when the preparation changes (invalidates cached beds)


def footprint(n):
    nx, _, _ = make_s1.lattice_dims(n)
    return nx * make_s1.SPACING * D


def fill_height(n):
    side = footprint(n)
    return n * math.pi / 6.0 * D ** 3 / (FILL_FRACTION * side * side)


def prep_params(n):
    return {"version": VERSION, "N": n, "fill_fraction": FILL_FRACTION, "restitution": PREP_RESTITUTION,
            "extra_s": PREP_EXTRA_S, "seed": PREP_SEED}


def deck(name, description, n, restitution, friction, box_top, subdomain, steps, output):
    """The scenario both the preparation and the benchmark use: S1's material, time step and skin, one subdomain
    'bed' of Hertz + restitution + Mindlin spheres (plus `subdomain`'s keys) in a box of S1's footprint."""
    side = round(footprint(n), 12)
    sd = {"name": "bed", "material": "beads",
          "contact": {"normal": {"model": "hertz"}, "damping": {"model": "restitution"},
                      "tangential": {"model": "mindlin"}},
          "time_step": DT, "skin": SKIN}
    for key, value in subdomain.items():
        if key == "contact":
            sd["contact"].update(value)
        else:
            sd[key] = value
    return {
        "name": name,
        "description": description,
        "gravity": [0, 0, -9.81],
        "materials": {"beads": {"density": RHO, "youngs_modulus": E, "poisson_ratio": NU}},
        "interactions": [{"materials": ["beads", "beads"], "restitution": restitution, "friction": friction}],
        "walls": [{"name": "box", "type": "box", "material": "beads", "min": [0, 0, 0],
                   "max": [side, side, round(box_top, 12)], "open": ["zmax"]}],
        "subdomains": [sd],
        "run": {"steps": steps, "seed": 1},
        "output": dict({"vtk_interval": 0, "probe_interval": 0}, **output),
    }


def prep_scenario(n):
    side = round(footprint(n), 12)
    h = fill_height(n)
    duration = math.sqrt(2.0 * h / 9.81) + PREP_EXTRA_S
    fill = {"model": "random", "region": {"box": {"min": [0, 0, 0], "max": [side, side, round(h, 12)]}},
            "diameter": D, "count": n, "seed": PREP_SEED}
    return deck("bed_prep_%s" % make_s1.label(n),
                "Preparation of the dense-bed benchmark (bench/make_bed.py): %d spheres fall frictionless "
                "from a random fill into a box" % n,
                n, PREP_RESTITUTION, 0.0, 1.05 * h + 2 * D, {"insert": [fill]}, int(math.ceil(duration / DT)),
                {"state": True})


def bed_scenario(n, top, rolling="none"):
    lab = make_s1.label(n)
    name = "bed_%s" % lab if rolling == "none" else "bed_%s_%s" % (lab, make_s1.ROLLING[rolling]["model"])
    return deck(name,
                "Dense settled-bed benchmark (bench/make_bed.py): %d spheres at rest, S1 material and "
                "contact model, run %d + %d steps with --time-after %d" % (n, NSETTLE, NRUN, NSETTLE),
                n, REST, MU, top,
                {"contact": {"rolling": dict(make_s1.ROLLING[rolling])}, "initial_state": "bed_%s.csv" % lab},
                NSETTLE + NRUN, {})


def read_state(path):
    rows = []
    with open(path) as f:
        header = None
        for line in f:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            if header is None:
                header = line.split(",")
                continue
            rows.append(dict(zip(header, line.split(","))))
    return rows


def paths(workdir, n):
    lab = make_s1.label(n)
    return {"csv": os.path.join(workdir, "bed_%s.csv" % lab), "data": os.path.join(workdir, "bed_%s.data" % lab),
            "meta": os.path.join(workdir, "bed_%s.meta.json" % lab)}


def cached(workdir, n):
    p = paths(workdir, n)
    if not all(os.path.isfile(v) for v in p.values()):
        return False
    with open(p["meta"]) as f:
        return json.load(f).get("prep") == prep_params(n)


def prepare(n, workdir, domel, threads=2, log=print):
    """Make bed_<label>.{csv,data,json} in workdir (reusing a cached bed); return the paths and bed facts."""
    os.makedirs(workdir, exist_ok=True)
    p = paths(workdir, n)
    if cached(workdir, n):
        with open(p["meta"]) as f:
            return p, json.load(f)
    scen = prep_scenario(n)
    spath = os.path.join(workdir, scen["name"] + ".json")
    with open(spath, "w") as f:
        f.write(make_s1.dumps(scen) + "\n")
    out = os.path.join(workdir, scen["name"] + "_out")
    log("preparing the bed for N = %d: %d steps of domel (%s) ..." % (n, scen["run"]["steps"], spath))
    shutil.rmtree(out, ignore_errors=True)  # domel refuses a folder with an earlier run's output
    subprocess.run([domel, "run", spath, "--out", out, "--quiet", "--threads", str(threads)], check=True)
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    rows = read_state(os.path.join(out, "bed_state.csv"))
    if len(rows) != n:
        raise RuntimeError("the preparation kept %d of %d particles" % (len(rows), n))
    side = footprint(n)
    zs = [float(r["z"]) + float(r["radius"]) for r in rows]
    top = max(zs)
    fin = summary["subdomains"][0]["final"]
    # solid fraction below 80 % of the bed's height, away from the top surface
    h80 = 0.8 * top
    vol = sum(4.0 / 3.0 * math.pi * float(r["radius"]) ** 3 for r in rows if float(r["z"]) < h80)
    facts = {"top_m": top, "contacts_per_particle_prep": 2.0 * fin["contacts"] / n,
             "ke_translational_prep_J": fin["ke_translational_J"], "solid_fraction_lower80": vol / (side * side * h80)}
    box_top = top + 2.0 * D
    with open(p["csv"], "w") as f:
        f.write("# dense bed for the domel/LIGGGHTS benchmark (bench/make_bed.py): %d particles at rest\n" % n)
        f.write("id,x,y,z,radius,vx,vy,vz,wx,wy,wz,fixed\n")
        for k, r in enumerate(rows):
            f.write("%d,%s,%s,%s,%s,0,0,0,0,0,0,0\n" % (k + 1, r["x"], r["y"], r["z"], r["radius"]))
    with open(p["data"], "w") as f:
        f.write("LIGGGHTS data file: dense bed for the domel/LIGGGHTS benchmark (bench/make_bed.py)\n\n")
        f.write("%d atoms\n1 atom types\n\n" % n)
        f.write("0 %.17g xlo xhi\n0 %.17g ylo yhi\n0 %.17g zlo zhi\n\n" % (side, side, box_top))
        f.write("Atoms\n\n")
        for k, r in enumerate(rows):
            f.write("%d 1 %.17g %.17g %s %s %s\n" % (k + 1, 2.0 * float(r["radius"]), RHO, r["x"], r["y"], r["z"]))
    facts.update(prep=prep_params(n), box_top_m=box_top)
    with open(p["meta"], "w") as f:
        json.dump(facts, f, indent=1)
    log("bed N = %d: top %.4f m, solid fraction %.3f (lower 80 %%), %.2f contacts per particle, kinetic energy "
        "%.3g J at the end of the preparation" % (n, top, facts["solid_fraction_lower80"],
                                                  facts["contacts_per_particle_prep"], facts["ke_translational_prep_J"]))
    return p, facts


def scenario_file(n, workdir, rolling="none"):
    """Write the domel benchmark scenario for a prepared bed; return its path."""
    with open(paths(workdir, n)["meta"]) as f:
        meta = json.load(f)
    scen = bed_scenario(n, meta["box_top_m"], rolling)
    path = os.path.join(workdir, scen["name"] + ".json")
    with open(path, "w") as f:
        f.write(make_s1.dumps(scen) + "\n")
    return path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[10000, 50000])
    ap.add_argument("--workdir", default=os.path.join(HERE, "work"))
    ap.add_argument("--domel", default=os.path.join(os.path.dirname(HERE), "build-bench", "bin", "domel"))
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args(argv)
    for n in args.sizes:
        prepare(n, os.path.abspath(args.workdir), args.domel, args.threads)
        print(scenario_file(n, os.path.abspath(args.workdir)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
