#!/usr/bin/env python3
"""Writes cg_heap_slot_<model>_a<alpha>_s<seed>.json (or cg_heap_<model>_a<alpha>_s<seed>.json with --geometry
cone): the coarse-grain invariance deck of the angle of repose (issue 15, item 2; docs/validation/coarse_grain_repose.md).

One bulk, built at coarse-grain ratios alpha = 1, 2, 3, collapses from a column whose wall is removed and comes to
rest on a rough floor until --duration. Material, contact laws and the probe are those of the repose deck
(make_repose.py; shared/peers/liggghts/repose.in): d = 2.8 mm, rho = 2500, E = 5 MPa, nu = 0.3, e = 0.5, mu = 0.5,
Hertz-Mindlin, time step "auto" (domel scales it with the parcels' contact).

--geometry slot (the default): a planar heap. A rectangular column of 48 x 30 x 66 cells of the alpha = 1 lattice
(constant 1.02 d; 137 x 86 x 189 mm, 95,040 particles) stands against the back wall (x = 0) of a slot 86 mm wide
and 0.8 m long; its gate (x = 137 mm) is removed at 0.2 s and the column collapses along +x. At ratio alpha the same
box holds 95040/alpha^3 parcels of diameter alpha d on a lattice of constant 1.02 alpha d (the cell counts are
divisible by 2 and 3), so bulk mass and column shape are exactly equal at alpha = 1, 2, 3. The slot's walls are
frictionless: they act as mirror planes, so the heap is one half of a planar heap of unbounded width (domel has no
periodic boundaries yet). The probe fits the planar slope with its crest at the back wall (repose_angle shape
"planar", crest 0). Why planar: the issue asks for a heap at least about 15 parcel diameters tall at alpha = 3; a
cone that tall holds about 1.2 million particles at alpha = 1, the half planar heap about 100,000.

--shrink k (slot only) divides every length of the slot and the column, not the particles, by k: at alpha = 1 the
deck is then, counted in particle diameters, the alpha = k deck built of real particles (95040/k^3 of them). Comparing
the two separates what coarse-graining changes from what a smaller heap changes.

--geometry cone: the first deck (kept to reproduce its runs): N1 (--n1, default 100000) particles' worth of material
on a simple-cubic lattice (a = 1.02 alpha d, jitter +-0.5 % of the parcel diameter) in a cylinder with the repose
deck's aspect height/diameter (--aspect, default 0.65), removed at 0.3 s. The lattice fits fewer whole parcels into
the same radius at larger alpha and the count is kept, so the column grows taller with alpha (111/120/129 mm).

Both: the floor is a layer of fixed spheres of the parcels' own diameter (alpha d) on a frictional plane, so the
floor is the coarse-grained image of the alpha = 1 floor, as every other length at the particle scale is. A flat
wall would be the same at every alpha, but without rolling resistance spheres roll on it forever, so the 'none'
heap would have no base to stand on.

Models (--models): sd5 (sd_critical_angle, theta_c = 5.71 deg = atan 0.1), sd20 (theta_c = 20 deg), none, dct
(mu_r = tan 5.71 deg). Usage:
    make_cg_heap.py [--geometry slot|cone] [--shrink 1|2|3|6] [--alphas 1 2 3] [--models sd5 sd20 none dct] [--seeds 15485863 ...]
                    [--duration 1.3] [--n1 100000] [--aspect 0.65] [--out DIR]
"""
import argparse
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_repose import D, SPACING, collapse_deck  # noqa: E402  (same folder: the repose deck's builder)

FLOOR_R = 0.28
MODELS = {
    "sd5": {"model": "sd_critical_angle", "critical_angle": math.degrees(math.atan(0.1))},
    "sd20": {"model": "sd_critical_angle", "critical_angle": 20.0},
    "none": {"model": "none"},
    "dct": {"model": "dct", "critical_angle": math.degrees(math.atan(0.1))},
}


def sites_per_layer(radius, a, d):
    """Sites of one layer of a simple-cubic lattice (constant a, anchored at the origin) whose sphere of diameter d
    lies inside this radius (as plugins/insertion/lattice.hpp counts them)."""
    n = int(math.ceil(radius / a)) + 1
    return sum(1 for i in range(-n, n) for j in range(-n, n)
               if math.hypot((i + 0.5) * a, (j + 0.5) * a) + 0.5 * d <= radius)


def column_radius(n1, aspect):
    """Radius of the cylinder whose height 2 aspect R holds n1 lattice cells of (1.02 d)^3."""
    return (n1 * (SPACING * D) ** 3 / (2.0 * math.pi * aspect)) ** (1.0 / 3.0)


# The slot: cells of the alpha = 1 lattice (constant SPACING * D) along x (column length), y (slot width) and z
# (column height); each divisible by 6, so that alpha = 1, 2 and 3 fill the same box with whole parcels.
SLOT_CELLS = (48, 30, 66)
SLOT_LENGTH = 0.8  # [m] floor and slot length along x: the particles that roll off the toe stop before its end
SLOT_GATE_AT = 0.2  # [s] the gate is removed once the column has settled


def slot_scenario(model, alpha, seed, duration, shrink=1):
    """The planar heap: a rectangular column against the back wall of a slot collapses along +x when its gate is
    removed. The slot's walls (back x = 0, sides y = 0 and y = W, gate) are frictionless, so they act as mirror
    planes: the heap is one half of a symmetric planar heap of unbounded width, without periodic boundaries.
    shrink > 1 divides every length of the slot and the column (not the particles) by shrink: at alpha = 1 and
    shrink k the deck is, in particle diameters, the alpha = k deck, with real particles."""
    if any(n % shrink for n in SLOT_CELLS):
        sys.exit("make_cg_heap.py: --shrink must divide the slot's cell counts %s" % (SLOT_CELLS,))
    nx, ny, nz = (n // shrink for n in SLOT_CELLS)
    if any(n % alpha for n in (nx, ny, nz)):
        sys.exit("make_cg_heap.py: the slot holds whole parcels only for alpha dividing %s" % ((nx, ny, nz),))
    dp, a = alpha * D, SPACING * alpha * D
    cell1 = SPACING * D
    length, width, height = nx * cell1, ny * cell1, nz * cell1
    count = int(round(nx * ny * nz / alpha ** 3))
    doc = collapse_deck(
        "cg_heap_slot_%s%s_a%g_s%d" % ("k%d_" % shrink if shrink > 1 else "", model, alpha, seed),
        "Coarse-grain invariance of the angle of repose, planar heap (make_cg_heap.py --geometry slot): %d "
        "particles' worth of material at alpha = %g (%d parcels of %.2f mm) in a column %.0f mm long and %.0f mm "
        "tall against the back wall of a frictionless slot %.1f mm wide collapse along +x onto a rough floor of "
        "fixed parcels when the gate opens at %g s; rolling %s." % (
            nx * ny * nz, alpha, count, 1e3 * dp, 1e3 * length, 1e3 * height, 1e3 * width, SLOT_GATE_AT,
            json.dumps(MODELS[model])),
        dict(MODELS[model]), seed, column_top=a + height,
        floor_region={"box": {"min": [0.0, 0.0, 0.0], "max": [SLOT_LENGTH / shrink, width, dp]}},
        parcel=dp, remove_at=SLOT_GATE_AT, duration=duration)
    doc["materials"]["mirror"] = dict(doc["materials"]["beads"])
    doc["interactions"].append({"materials": ["beads", "mirror"], "restitution": 0.5, "friction": 0.0})
    doc["walls"] = [
        {"name": "slot", "type": "box", "material": "mirror", "min": [0.0, 0.0, 0.0],
         "max": [SLOT_LENGTH / shrink, width, a + 1.5 * height], "open": ["zmax"]},
        {"name": "gate", "type": "plane", "material": "mirror", "point": [length, 0.0, 0.0],
         "normal": [-1.0, 0.0, 0.0], "remove_at": SLOT_GATE_AT},
    ]
    sd = doc["subdomains"][0]
    sd["coarse_grain"] = alpha
    sd["time_step"] = "auto"
    sd["insert"][1]["count"] = count
    sd["insert"][1]["region"] = {"box": {"min": [0.0, 0.0, a], "max": [length, width, a + height]}}
    doc["output"]["state"] = True
    doc["output"]["repose_angle"].update({"shape": "planar", "axis": "x", "crest": 0.0})
    return doc, count, count * alpha ** 3 / (nx * ny * nz), height


def cone_scenario(model, alpha, seed, n1, duration, aspect):
    rc = column_radius(n1, aspect)
    dp, a = alpha * D, SPACING * alpha * D
    target = int(round(n1 / alpha ** 3))
    layers = int(math.ceil(target / sites_per_layer(rc - 0.5 * a + 0.5 * dp, a, dp)))
    doc = collapse_deck(
        "cg_heap_%s_a%g_s%d" % (model, alpha, seed),
        "Coarse-grain invariance of the angle of repose (make_cg_heap.py): %d particles' worth of material at "
        "alpha = %g (%d parcels of %.2f mm) collapse from a cylinder of R = %.0f mm onto a rough floor of fixed "
        "parcels; rolling %s." % (n1, alpha, target, 1e3 * dp, 1e3 * rc, json.dumps(MODELS[model])),
        dict(MODELS[model]), seed, column_top=(layers + 1.5) * a,
        floor_region={"cylinder": {"axis": "z", "center": [0, 0, 0], "radius": FLOOR_R, "bottom": 0.0, "top": dp}},
        parcel=dp, rc=rc, box=(0.32, 0.5), remove_at=0.3, duration=duration)
    sd = doc["subdomains"][0]
    sd["coarse_grain"] = alpha
    sd["time_step"] = "auto"
    sd["insert"][1]["count"] = target
    doc["output"]["state"] = True
    return doc, target, target * alpha ** 3 / n1, layers * a


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--alphas", type=float, nargs="+", default=[1, 2, 3])
    ap.add_argument("--models", nargs="+", default=list(MODELS), choices=sorted(MODELS))
    ap.add_argument("--seeds", type=int, nargs="+", default=[15485863])
    ap.add_argument("--n1", type=int, default=100000, help="cone: particles' worth of material at alpha = 1")
    ap.add_argument("--duration", type=float, default=None,
                    help="simulated time in s (default: 1.3 slot, 2.0 cone)")
    ap.add_argument("--aspect", type=float, default=0.65, help="cone: column height / column diameter")
    ap.add_argument("--geometry", choices=["slot", "cone"], default="slot")
    ap.add_argument("--shrink", type=int, default=1, choices=[1, 2, 3, 6],
                    help="slot: divide the slot's lengths (not the particles) by this factor")
    ap.add_argument("--out", default=".")
    args = ap.parse_args(argv)
    if any(a < 1 for a in args.alphas):
        ap.error("--alphas must be >= 1")
    os.makedirs(args.out, exist_ok=True)
    for alpha in args.alphas:
        for model in args.models:
            for seed in args.seeds:
                if args.geometry == "slot":
                    doc, n, mass_ratio, height = slot_scenario(model, alpha, seed, args.duration or 1.3, args.shrink)
                else:
                    doc, n, mass_ratio, height = cone_scenario(model, alpha, seed, args.n1, args.duration or 2.0,
                                                               args.aspect)
                path = os.path.join(args.out, doc["name"] + ".json")
                with open(path, "w") as f:
                    json.dump(doc, f, indent=2)
                    f.write("\n")
                print("%s: %d parcels (bulk mass %.4f of the target), column %.0f mm tall" % (
                    path, n, mass_ratio, 1e3 * height))
    return 0


if __name__ == "__main__":
    sys.exit(main())
