#!/usr/bin/env python3
"""Writes repose_{sd,dct,none}.json: domel's version of the peers' S3 'repose'
deck (shared/peers/liggghts/repose.in): a 15-layer simple-cubic column
(a = 1.02 d, d = 2.8 mm, S1 material) settles for 0.25 s inside a cylinder
(R = 33 mm) on a rough floor of 68 x 68 fixed spheres, the cylinder is
removed and the heap settles until t = 1.25 s. Rolling resistance: dct with
mu_r = 0.1 (LIGGGHTS cdt), sd_critical_angle with theta_c = atan(0.1)
(compared with LIGGGHTS epsd2), or none. Lattices are anchored at the origin
as LIGGGHTS' 'lattice sc ... origin 0.5 0.5 0.5' is, so the counts match
(4624 floor + 5760 mobile). With --epsd-library PATH it also writes
repose_epsd2.json: the out-of-tree example plugin (examples/third_party_rolling,
built as libdomel_rolling_epsd.so), loaded from PATH, as LIGGGHTS epsd2 with
mu_r = 0.1 (Iwashita-Oda stiffness, no dashpot): the same model in both codes.
With --theta-c DEG [DEG ...] it also writes repose_sd_tc<DEG>.json:
sd_critical_angle at those critical angles (0 means no rolling resistance),
for the theta_c -> angle-of-repose curve of docs/rolling.md.
With --material chamber the contacts are those of the DEM-CFD chamber's glass
beads (restitution 0.9, sliding friction 0.3; scenarios/fluid/make_chamber.py)
instead of the repose deck's (0.5, 0.5), everything else the same, and the
files are named repose_chamber_<tag>: the curve from which the chamber's
theta_c is read (docs/validation/chamber.md).
Usage: make_repose.py [seed] [--epsd-library PATH] [--theta-c DEG [DEG ...]] [--material repose|chamber]"""
import json, math, os, sys

D = 0.0028
SPACING = 1.02
RC = 0.033
# the scenarios' description: the deck, without the generator's options
DECK = " ".join(__doc__.split("Rolling resistance:")[0].split()).replace("Writes repose_{sd,dct,none}.json: ", "", 1)
# the bead-bead contact of each material the deck is made with: (restitution, sliding friction)
MATERIALS = {"repose": (0.5, 0.5), "chamber": (0.9, 0.3)}


def collapse_deck(name, description, rolling, seed, column_top, floor_region, parcel=D, rc=RC, box=(0.1, 0.1),
                  plugins=None, remove_at=0.25, duration=1.25, contact=MATERIALS["repose"]):
    """A column of lattice spheres (d = D, constant SPACING parcel diameters) in a cylinder of radius rc, removed at
    remove_at, collapsing onto a floor of fixed spheres (floor_region) in a box of half-width box[0] and height
    box[1]; the repose deck's material and contact laws, contact = (restitution, friction). parcel is the diameter after coarse-graining (D at
    alpha = 1): it sets the column region's margins and the probe's base height."""
    a = SPACING * parcel
    return {
        "$schema": "../../docs/domel.schema.json",
        "name": name,
        "description": description,
        **({"plugins": list(plugins)} if plugins else {}),
        "gravity": [0, 0, -9.81],
        "materials": {"beads": {"density": 2500, "youngs_modulus": 5e6, "poisson_ratio": 0.3}},
        "interactions": [{"materials": ["beads", "beads"], "restitution": contact[0], "friction": contact[1]}],
        "walls": [
            {"name": "box", "type": "box", "material": "beads", "min": [-box[0], -box[0], 0.0],
             "max": [box[0], box[0], box[1]], "open": ["zmax"]},
            {"name": "cylinder", "type": "cylinder", "material": "beads", "axis": "z", "center": [0, 0, 0],
             "radius": rc, "bottom": 0.0, "top": box[1], "closed_bottom": False, "remove_at": remove_at},
        ],
        "subdomains": [{
            "name": "heap", "material": "beads",
            "contact": {"normal": {"model": "hertz"}, "damping": {"model": "restitution"},
                        "tangential": {"model": "mindlin"}, "rolling": rolling},
            "time_step": 1e-5, "skin": 0.5,
            "insert": [
                {"model": "lattice", "fixed": True, "diameter": D, "spacing": 1.0, "origin": [0, 0, 0],
                 "region": floor_region},
                {"model": "lattice", "diameter": D, "spacing": SPACING, "jitter": 0.005, "origin": [0, 0, 0],
                 "seed": seed,
                 "region": {"cylinder": {"axis": "z", "center": [0, 0, 0], "radius": rc - 0.5 * a + 0.5 * parcel,
                                         "bottom": a, "top": column_top}}},
            ],
        }],
        "run": {"duration": duration, "seed": 1},
        "output": {"vtk_interval": 0.25, "probe_interval": 0.01, "repose_angle": {"base_height": parcel}},
    }


def main():
    args = sys.argv[1:]
    library = None
    if "--epsd-library" in args:
        k = args.index("--epsd-library")
        if k + 1 >= len(args):
            sys.exit("make_repose.py: --epsd-library needs the path of libdomel_rolling_epsd.so")
        library = os.path.abspath(args[k + 1])
        if not os.path.isfile(library):
            sys.exit(f"make_repose.py: --epsd-library: no file {library}")
        del args[k:k + 2]
    angles = []
    if "--theta-c" in args:
        k = args.index("--theta-c")
        rest = args[k + 1:]
        n = 0
        while n < len(rest) and rest[n].replace(".", "", 1).isdigit():
            n += 1
        if n == 0:
            sys.exit("make_repose.py: --theta-c needs one or more angles in degrees")
        angles = [float(x) for x in rest[:n]]
        if any(not 0.0 <= x < 90.0 for x in angles):
            sys.exit("make_repose.py: --theta-c angles must lie in [0, 90) degrees")
        del args[k:k + 1 + n]
    material = "repose"
    if "--material" in args:
        k = args.index("--material")
        if k + 1 >= len(args) or args[k + 1] not in MATERIALS:
            sys.exit("make_repose.py: --material needs one of " + ", ".join(MATERIALS))
        material = args[k + 1]
        del args[k:k + 2]
    prefix = "repose_" if material == "repose" else f"repose_{material}_"
    restitution, friction = MATERIALS[material]
    deck = DECK if material == "repose" else DECK.replace(
        "S1 material)", f"S1 material; restitution {restitution}, friction {friction}: the DEM-CFD chamber's beads)")

    seed = int(args[0]) if args else 15485863
    suffix = f"_s{seed}" if args else ""
    models = {
        "sd": {"model": "sd_critical_angle", "critical_angle": math.degrees(math.atan(0.1))},
        "dct": {"model": "dct", "rolling_friction": 0.1},
        "none": {"model": "none"},
    }
    for deg in angles:
        models[f"sd_tc{deg:g}"] = ({"model": "none"} if deg == 0.0 else
                                   {"model": "sd_critical_angle", "critical_angle": deg})
    if library:
        models["epsd2"] = {"model": "epsd", "rolling_friction": 0.1, "stiffness": "iwashita_oda", "dashpot": False}
    for tag, rolling in models.items():
        doc = collapse_deck(f"{prefix}{tag}{suffix}", deck + " Rolling resistance: " + json.dumps(rolling) + ".",
                            rolling, seed, column_top=16 * SPACING * D,
                            floor_region={"box": {"min": [-0.0953, -0.0953, 0.0], "max": [0.0953, 0.0953, D]}},
                            plugins=[library] if tag == "epsd2" else None, contact=(restitution, friction))
        with open(f"{prefix}{tag}{suffix}.json", "w") as f:
            json.dump(doc, f, indent=2)
            f.write("\n")


if __name__ == "__main__":
    main()
