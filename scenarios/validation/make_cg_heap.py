#!/usr/bin/env python3
"""Writes cg_heap_<model>_a<alpha>[_s<seed>].json: the coarse-grain invariance deck of the angle of repose.

One bulk, built at coarse-grain ratios alpha = 1, 2, 3: a column of N1 particles' worth of material (N1 = 100000 at
alpha = 1 by default; N1/alpha^3 parcels of diameter alpha d at ratio alpha) on a simple-cubic lattice (a = 1.02
alpha d, jitter +-0.5 % of the parcel diameter) settles for 0.3 s inside a cylinder that is then removed, and the
heap collapses and comes to rest until --duration (default 2.0 s). Material, contact laws and the probe are those of
the repose deck (make_repose.py; shared/peers/liggghts/repose.in): d = 2.8 mm, rho = 2500, E = 5 MPa, nu = 0.3,
e = 0.5, mu = 0.5, Hertz-Mindlin, repose_angle probe.

Choices (issue 15, item 2):
- The column's outer size is the same at every alpha: the radius Rc and the height that hold N1 (1.02 d)^3 of
  lattice at the aspect height/diameter --aspect (default 0.65, the repose deck's: 15 layers in R = 33 mm), so the
  bulk mass is the same to within the lattice's rounding (printed). A taller column collapses further and leaves a
  flatter heap (at aspect 1.5 and alpha = 3 the angle was 12-14 deg against 19-21 deg on the repose deck).
- The floor is a layer of fixed spheres of the parcels' own diameter (alpha d) on a frictional plane, under a disk
  of radius 0.28 m: the floor is then the coarse-grained image of the alpha = 1 floor, as every other length at the
  particle scale is. A flat wall would be the same at every alpha, but without rolling resistance spheres roll on
  it forever, so the 'none' heap would have no base to stand on.
- Time step: "auto" (domel scales the estimate with the parcels' contact).
- Size: 100k particles make a cone only about 9 parcel diameters tall at alpha = 3 (at 20-25 deg), below the
  issue's "about 15"; --n1 sets more, at a cost of about 25 min per 100k at alpha = 1 on one core.

Models (--models): sd5 (sd_critical_angle, theta_c = 5.71 deg = atan 0.1), sd20 (theta_c = 20 deg), none, dct
(mu_r = tan 5.71 deg). Usage:
    make_cg_heap.py [--alphas 1 2 3] [--models sd5 sd20 none dct] [--seeds 15485863 ...] [--n1 100000]
                    [--duration 2.0] [--aspect 0.65] [--out DIR]
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


def scenario(model, alpha, seed, n1, duration, aspect):
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
    ap.add_argument("--n1", type=int, default=100000, help="particles' worth of material at alpha = 1")
    ap.add_argument("--duration", type=float, default=2.0)
    ap.add_argument("--aspect", type=float, default=0.65, help="column height / column diameter")
    ap.add_argument("--out", default=".")
    args = ap.parse_args(argv)
    if any(a < 1 for a in args.alphas):
        ap.error("--alphas must be >= 1")
    os.makedirs(args.out, exist_ok=True)
    for alpha in args.alphas:
        for model in args.models:
            for seed in args.seeds:
                doc, n, mass_ratio, height = scenario(model, alpha, seed, args.n1, args.duration, args.aspect)
                path = os.path.join(args.out, doc["name"] + ".json")
                with open(path, "w") as f:
                    json.dump(doc, f, indent=2)
                    f.write("\n")
                print("%s: %d parcels (bulk mass %.4f of the target), column %.0f mm tall" % (
                    path, n, mass_ratio, 1e3 * height))
    return 0


if __name__ == "__main__":
    sys.exit(main())
