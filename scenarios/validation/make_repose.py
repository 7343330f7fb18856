#!/usr/bin/env python3
"""Writes repose_{sd,dct,none}.json: domel's version of the peers' S3 'repose'
deck (shared/peers/liggghts/repose.in): a 15-layer simple-cubic column
(a = 1.02 d, d = 2.8 mm, S1 material) settles for 0.25 s inside a cylinder
(R = 33 mm) on a rough floor of 68 x 68 fixed spheres, the cylinder is
removed and the heap settles until t = 1.25 s. Rolling resistance: dct with
mu_r = 0.1 (LIGGGHTS cdt), sd_critical_angle with theta_c = atan(0.1)
(compared with LIGGGHTS epsd2), or none. Lattices are anchored at the origin
as LIGGGHTS' 'lattice sc ... origin 0.5 0.5 0.5' is, so the counts match
(4624 floor + 5760 mobile). Usage: make_repose.py [seed]"""
import json, math, sys

d = 0.0028
a = 1.02 * d
Rc = 0.033
seed = int(sys.argv[1]) if len(sys.argv) > 1 else 15485863
suffix = "" if len(sys.argv) <= 1 else f"_s{seed}"
models = {
    "sd": {"model": "sd_critical_angle", "critical_angle": math.degrees(math.atan(0.1))},
    "dct": {"model": "dct", "rolling_friction": 0.1},
    "none": {"model": "none"},
}
for tag, rolling in models.items():
    doc = {
        "$schema": "../../docs/domel.schema.json",
        "name": f"repose_{tag}{suffix}",
        "description": __doc__.split("Usage")[0].strip().replace("\n", " "),
        "gravity": [0, 0, -9.81],
        "materials": {"beads": {"density": 2500, "youngs_modulus": 5e6, "poisson_ratio": 0.3}},
        "interactions": [{"materials": ["beads", "beads"], "restitution": 0.5, "friction": 0.5}],
        "walls": [
            {"name": "box", "type": "box", "material": "beads", "min": [-0.1, -0.1, 0.0], "max": [0.1, 0.1, 0.1],
             "open": ["zmax"]},
            {"name": "cylinder", "type": "cylinder", "material": "beads", "axis": "z", "center": [0, 0, 0],
             "radius": Rc, "bottom": 0.0, "top": 0.1, "closed_bottom": False, "remove_at": 0.25},
        ],
        "subdomains": [{
            "name": "heap", "material": "beads",
            "contact": {"normal": {"model": "hertz"}, "damping": {"model": "restitution"},
                        "tangential": {"model": "mindlin"}, "rolling": rolling},
            "time_step": 1e-5, "skin": 0.5,
            "insert": [
                {"model": "lattice", "fixed": True, "diameter": d, "spacing": 1.0, "origin": [0, 0, 0],
                 "region": {"box": {"min": [-0.0953, -0.0953, 0.0], "max": [0.0953, 0.0953, d]}}},
                {"model": "lattice", "diameter": d, "spacing": 1.02, "jitter": 0.005, "origin": [0, 0, 0],
                 "seed": seed,
                 "region": {"cylinder": {"axis": "z", "center": [0, 0, 0], "radius": Rc - 0.5 * a + 0.5 * d,
                                         "bottom": a, "top": 16 * a}}},
            ],
        }],
        "run": {"duration": 1.25, "seed": 1},
        "output": {"vtk_interval": 0.25, "probe_interval": 0.01, "repose_angle": {"base_height": d}},
    }
    with open(f"repose_{tag}{suffix}.json", "w") as f:
        json.dump(doc, f, indent=2)
        f.write("\n")
