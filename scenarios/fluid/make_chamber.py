#!/usr/bin/env python3
"""Writes the mission's DEM-CFD chamber scenarios (issue 16 item 5;
docs/validation/chamber.md gives every choice and its reason):

  chamber_a{4,6,8}_none.json  fed into the plate's wake; no rolling resistance
  chamber_a{4,6,8}_sd.json    the same with sd_critical_angle, theta_c = THETA_C
  chamber_bottom_a{4,8}.json  fed near the floor instead, for 0.3 s: do the
                              beads rise past the plate, and do any settle on it?
  chamber_bottom_a4_unscaled.json  the same at alpha = 4 with the drag evaluated
                              at the parcel's own diameter (coarse-grain scaling off)
  chamber_spout_a8_{none,sd}.json  fed as a narrow stream falling at 0.5 m/s
                              (a spout) instead of a sieve's rain
  chamber_heap_a{4,6,8}_{none,sd}_s{1,2}.json  the heap runs (issue 45 item 3):
                              the same 3.35 g released at rest over the plate's
                              centre (radius HEAP_FEED_R) within HEAP_FEED_TIME, so
                              a heap builds up to the plate's rim; the repose
                              deck's contacts (HEAP_CONTACT); S-D at theta_c =
                              THETA_C_GLASS; van Leer advection; two seeds
  chamber_still_a{4,6,8}_{none,sd}_s{1,2}.json  the same heap feed in still air
                              (no gas): the control of item 4

The geometry and the gas are the paper's: a 200 mm tall chamber of
40 x 40 mm, a circular plate of 23 mm diameter 140 mm above the floor, air
rising at 1.5 m/s; 100 um glass beads, 3.35 g of them (2.56 million
originals). The beads are fed at a constant mass rate into the plate's wake, as from
a sieve above the plate: released at rest in a cylinder over the plate
(radius 10.5 mm, 12-22 mm above it), where the gas is slower than their
terminal velocity, so they settle on the plate; what rolls off its rim
meets the fast gas beside it and is carried out at the top. The bottom-fed
runs show why the feed is there: beads fed near the floor rise past the
plate, and almost none of them enter its wake.
The heap runs are not shipped (24 near-copies): --heaps writes them, and only
them, into OUTDIR; scenarios/fluid/run_chamber.sh OUTDIR JOBS heaps does that
itself.
Usage: make_chamber.py [--heaps] [OUTDIR] (default: this script's folder)."""
import copy
import json
import math
import os
import sys

D = 100e-6            # bead diameter [m]
RHO = 2500.0          # glass [kg/m^3]
TOTAL = 3.35e-3       # fed mass [kg], the paper's 2.56 million beads
FEED_TIME = 1.0       # [s] the mass is fed at TOTAL / FEED_TIME
DURATION = 2.0        # [s]
SIDE, HEIGHT = 0.04, 0.2
PLATE_Z, PLATE_R = 0.140, 0.0115
U_AIR = 1.5           # superficial gas velocity at the inlet [m/s]
THETA_C = 5.710593137499643  # tan(theta_c) = 0.1, the repose validation's value
CELL = 0.0025         # fluid cell [m]: 3.1 parcel diameters at alpha = 8
# The heap runs: the beads are released at rest over the plate's centre, inside the wake's down-flow, so that a heap
# builds from the centre out to the rim (a cone on the plate at 26 deg holds about 1.2 g); the same feed at every alpha.
HEAP_FEED_R = 0.004   # [m] radius of the feed's cylinder over the plate's centre, 12-32 mm above it
HEAP_FRACTION = 0.1   # solids fraction of one filled feed region: 251 mg, more than the 214 mg of one refill interval (the
                      # 64 ms a bead takes to fall through the region) at 3.35 g/s
HEAP_FEED_TIME = 1.0  # [s]
HEAP_DURATION = 1.5   # [s]: the feed, then 0.5 s for what stays on the plate to come to rest
# The heap runs' bead-bead contact (restitution, sliding friction): the repose deck's, whose theta_c -> angle curve
# (docs/rolling.md, three seeds) reaches a glass-bead heap's angle; with the chamber's (0.9, 0.3) the curve levels
# off at about 23 deg (docs/rolling.md, "The same deck with the chamber's glass beads").
HEAP_CONTACT = (0.5, 0.5)
# theta_c of the heap runs' S-D model: where the repose deck's curve (docs/rolling.md, medians of three seeds:
# 25.53 deg at 25, 28.85 deg at 30) reaches 26 deg, the angle of repose of 0.15 mm glass beads (Makse et al.
# 1997; docs/validation/chamber.md), by linear interpolation
THETA_C_GLASS = 25.7


def scenario(alpha, rolling, scaling=True, feed="wake", seed=1):
    theta_c, fed_time = THETA_C, FEED_TIME
    if feed in ("heap", "still"):
        name = f"chamber_{feed}_a{alpha}_{rolling}_s{seed}"
        region = {"cylinder": {"axis": "z", "center": [SIDE / 2, SIDE / 2, 0], "radius": HEAP_FEED_R,
                               "bottom": PLATE_Z + 0.012, "top": PLATE_Z + 0.032}}
        velocity, fraction, duration = [0, 0, 0], HEAP_FRACTION, HEAP_DURATION
        theta_c, fed_time = THETA_C_GLASS, HEAP_FEED_TIME
    elif feed == "wake":
        name = f"chamber_a{alpha}_{rolling}"
        region = {"cylinder": {"axis": "z", "center": [SIDE / 2, SIDE / 2, 0], "radius": PLATE_R - 0.001,
                               "bottom": PLATE_Z + 0.012, "top": PLATE_Z + 0.022}}
        velocity, fraction, duration = [0, 0, 0], 0.05, DURATION
    elif feed == "spout":
        name = f"chamber_spout_a{alpha}_{rolling}"
        region = {"cylinder": {"axis": "z", "center": [SIDE / 2, SIDE / 2, 0], "radius": 0.006,
                               "bottom": PLATE_Z + 0.012, "top": PLATE_Z + 0.022}}
        velocity, fraction, duration = [0, 0, -0.5], 0.1, DURATION
    else:
        name = f"chamber_bottom_a{alpha}" + ("" if scaling else "_unscaled")
        region = {"box": {"min": [0.001, 0.001, 0.005], "max": [SIDE - 0.001, SIDE - 0.001, 0.025]}}
        velocity, fraction, duration = [0, 0, 0.9], 0.005, 0.3
    # the heap's region: over the plate up to 10 mm (a heap at 30 deg is 6.6 mm
    # tall), below the feed
    heap = {"cylinder": {"axis": "z", "center": [SIDE / 2, SIDE / 2, 0], "radius": PLATE_R + 0.001,
                         "bottom": PLATE_Z, "top": PLATE_Z + 0.01}}
    contact = {"normal": {"model": "hertz"}, "damping": {"model": "restitution"},
               "tangential": {"model": "mindlin"}}
    if rolling == "sd":
        contact["rolling"] = {"model": "sd_critical_angle", "critical_angle": theta_c}
    n = int(round(TOTAL / (RHO * math.pi / 6 * (alpha * D) ** 3)))
    where = {"bottom": "the floor", "heap": "the plate's centre", "still": "the plate's centre"}.get(feed, "the plate")
    doc = {
        "$schema": "../../docs/domel.schema.json",
        "name": name,
        "description": (
            f"DEM-CFD chamber (issue 16 item 5): 200 x 40 x 40 mm, a plate of 23 mm at 140 mm, air at "
            f"{U_AIR} m/s; {TOTAL * 1e3} g of 100 um glass beads as about {n} parcels of alpha = {alpha}, fed near "
            f"{where} over {fed_time} s; rolling resistance: {rolling if scaling else 'none'}; drag "
            f"coarse-grain scaling {'on' if scaling else 'OFF (the parcels feel the drag of a bead of their own size)'}. "
            "Written by scenarios/fluid/make_chamber.py; docs/validation/chamber.md."),
        "gravity": [0, 0, -9.81],
        "materials": {"glass": {"density": RHO, "youngs_modulus": 5e6, "poisson_ratio": 0.3}},
        "interactions": [{"materials": ["glass", "glass"], "restitution": 0.9, "friction": 0.3}],
        "walls": [
            {"name": "chamber", "type": "box", "material": "glass", "min": [0, 0, 0],
             "max": [SIDE, SIDE, HEIGHT], "open": ["zmax"]},
            {"name": "plate", "type": "disk", "material": "glass", "center": [SIDE / 2, SIDE / 2, PLATE_Z],
             "normal": [0, 0, 1], "radius": PLATE_R},
        ],
        "subdomains": [{
            "name": "beads", "material": "glass", "coarse_grain": alpha, "contact": contact,
            "pour": [{
                "insert": {"model": "random", "diameter": D, "volume_fraction": fraction,
                           "region": region, "velocity": velocity},
                "mass_rate": TOTAL / fed_time, "total_mass": TOTAL}],
        }],
        "deletion_regions": [{"name": "top_outlet", "region": {"box": {"min": [0, 0, HEIGHT - 0.01],
                                                                         "max": [SIDE, SIDE, HEIGHT]}}}],
        "fluid": {
            "model": "vans", "interval": 2e-4, "substeps": "auto",
            "grid": {"min": [0, 0, 0], "max": [SIDE, SIDE, HEIGHT],
                     "cells": [round(SIDE / CELL), round(SIDE / CELL), round(HEIGHT / CELL)]},
            "density": 1.2, "viscosity": 1.8e-5,
            "boundaries": {"x_min": {"type": "wall"}, "x_max": {"type": "wall"},
                           "y_min": {"type": "wall"}, "y_max": {"type": "wall"},
                           "z_min": {"type": "velocity_inlet", "velocity": [0, 0, U_AIR]},
                           "z_max": {"type": "pressure_outlet"}},
            "obstacles": [{"cylinder": {"axis": "z", "center": [SIDE / 2, SIDE / 2], "radius": PLATE_R,
                                        "min": PLATE_Z - 0.0015, "max": PLATE_Z - 0.0005}}],
            "initial_velocity": [0, 0, U_AIR],
            "drag": {"law": "di_felice", "coarse_grain_scaling": scaling},
            "write_interval": 0.05,
        },
        "run": {"duration": duration, "seed": seed, "deletion_interval": 0.002},
        "output": {
            "vtk_interval": 0.02, "probe_interval": 0.005,
            "mass_flow": [{"name": "past_plate", "point": [0, 0, PLATE_Z + 0.01], "normal": [0, 0, 1]}],
            "region_mass": [{"name": "plate_heap", "region": heap, "max_speed": 0.05},
                            {"name": "above_plate", "region": heap}],
            "repose_angle": {"region": heap, "max_speed": 0.05, "base_height": PLATE_Z},
        },
    }
    if feed in ("heap", "still"):
        restitution, friction = HEAP_CONTACT
        doc["interactions"][0].update(restitution=restitution, friction=friction)
        doc["description"] += (f" The heap runs (issue 45 items 3 and 4): restitution {restitution}, friction "
                               f"{friction} (the repose deck's), theta_c = {THETA_C_GLASS} deg, van Leer advection.")
        doc["fluid"]["advection"] = "van_leer"
    if feed == "still":
        del doc["fluid"]
        doc["description"] = doc["description"].replace(f"air at {U_AIR} m/s", "still air (no gas: the control)")
        doc["description"] = doc["description"].replace(", van Leer advection", "").replace(
            "; drag coarse-grain scaling on", "")
        # what falls past the rim cannot come back in still air: removed 20 mm below the plate
        doc["deletion_regions"].append({"name": "below_plate", "region": {"box": {
            "min": [0, 0, 0], "max": [SIDE, SIDE, PLATE_Z - 0.02]}}})
    return name, doc


def main():
    args = sys.argv[1:]
    heaps = "--heaps" in args
    args = [a for a in args if a != "--heaps"]
    out = args[0] if args else os.path.dirname(os.path.abspath(__file__))
    os.makedirs(out, exist_ok=True)
    runs = [(a, r, True, "wake") for a in (4, 6, 8) for r in ("none", "sd")]
    runs += [(4, "none", True, "bottom"), (8, "none", True, "bottom"), (4, "none", False, "bottom")]
    runs += [(8, r, True, "spout") for r in ("none", "sd")]
    runs = [(a, r, sc, f, 1) for a, r, sc, f in runs]
    if heaps:
        runs = [(a, r, True, f, seed) for f in ("heap", "still") for a in (4, 6, 8) for r in ("none", "sd")
                for seed in (1, 2)]
    for alpha, rolling, scaling, feed, seed in runs:
        name, doc = scenario(alpha, rolling, scaling, feed, seed)
        with open(os.path.join(out, name + ".json"), "w") as f:
            json.dump(doc, f, indent=2)
            f.write("\n")
        print(os.path.join(out, name + ".json"))


if __name__ == "__main__":
    main()
