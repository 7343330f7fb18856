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
Usage: make_chamber.py [OUTDIR] (default: this script's folder)."""
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


def scenario(alpha, rolling, scaling=True, feed="wake"):
    if feed == "wake":
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
        contact["rolling"] = {"model": "sd_critical_angle", "critical_angle": THETA_C}
    n = int(round(TOTAL / (RHO * math.pi / 6 * (alpha * D) ** 3)))
    return name, {
        "$schema": "../../docs/domel.schema.json",
        "name": name,
        "description": (
            f"DEM-CFD chamber (issue 16 item 5): 200 x 40 x 40 mm, a plate of 23 mm at 140 mm, air at "
            f"{U_AIR} m/s; {TOTAL * 1e3} g of 100 um glass beads as about {n} parcels of alpha = {alpha}, fed near "
            f"{'the floor' if feed == 'bottom' else 'the plate'} over {FEED_TIME} s; rolling resistance: {rolling if scaling else 'none'}; drag "
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
                "mass_rate": TOTAL / FEED_TIME, "total_mass": TOTAL}],
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
        "run": {"duration": duration, "seed": 1, "deletion_interval": 0.002},
        "output": {
            "vtk_interval": 0.02, "probe_interval": 0.005,
            "mass_flow": [{"name": "past_plate", "point": [0, 0, PLATE_Z + 0.01], "normal": [0, 0, 1]}],
            "region_mass": [{"name": "plate_heap", "region": heap, "max_speed": 0.05},
                            {"name": "above_plate", "region": heap}],
            "repose_angle": {"region": heap, "max_speed": 0.05, "base_height": PLATE_Z},
        },
    }


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    runs = [(a, r, True, "wake") for a in (4, 6, 8) for r in ("none", "sd")]
    runs += [(4, "none", True, "bottom"), (8, "none", True, "bottom"), (4, "none", False, "bottom")]
    runs += [(8, r, True, "spout") for r in ("none", "sd")]
    for alpha, rolling, scaling, feed in runs:
        name, doc = scenario(alpha, rolling, scaling, feed)
        with open(os.path.join(out, name + ".json"), "w") as f:
            json.dump(doc, f, indent=2)
            f.write("\n")
        print(os.path.join(out, name + ".json"))


if __name__ == "__main__":
    main()
