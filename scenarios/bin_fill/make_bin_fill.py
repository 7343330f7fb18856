#!/usr/bin/env python3
"""Writes the bin-fill scenarios beside LIGGGHTS-PFM's adaptive-resolution
example bin_fill (shared peers/PFM_RESULTS.md §2.1; docs/validation/multilevel.md):
a 40 x 20 mm bin, open at the top, filled from a block 0.10-0.12 m above its
floor at z = -0.02 m, with a window z in [0, 0.08] m resolved at the fine level.
  bin_fill_fine.json  all fine (d = 2 mm), the reference;
  bin_fill_2lvl.json  coarse (alpha = 2, d = 4 mm) everywhere, fine in the window,
                      coupled through the window's top and bottom faces.
Material as the example's: Hertz, E = 1e8 Pa, nu = 0.35, e = 0.6, rho = 2500
kg/m^3, friction 0.3 particle-particle and 0.5 particle-wall. The example's
rolling friction (epsd2, 0.01 / 0.02) is left out: domel has no epsd2 built in
(the rolling-model issue brings the like-for-like one).
Differences from the example, chosen for domel:
  - the feed is a pour at the mass rate the example delivered (87 g/s measured
    for its fine deck, PFM_RESULTS §5), every 0.5 ms as its refills, at both
    levels alike (the example's 45 instead of 48 coarse per refill starves its
    coarse level);
  - the coarse level steps at 2e-6 s (alpha dt), the fine one at 1e-6 s, the
    example's step;
  - the window's levels overlap in place (domel's levels never touch), instead
    of a shifted copy of the bin;
  - stress control only, as the example (velocity control off), with its
    layer (1.4 d) and gains (1/N, 1/(N dt)); shell 3 mm deep as its top face.
Usage: make_bin_fill.py"""
import json, os

HERE = os.path.dirname(os.path.abspath(__file__))
D = 0.002
WINDOW = {"min": [-0.02, -0.02, 0.0], "max": [0.02, 0.0, 0.08], "cells": [2, 1, 4]}


def level(name, alpha):
    return {"name": name, "material": "glass", "coarse_grain": alpha,
            "contact": {"normal": {"model": "hertz"}, "damping": {"model": "restitution"},
                        "tangential": {"model": "mindlin"}},
            "time_step": 1e-6 * alpha, "impact_velocity": 1.5}


def pour():
    return [{"insert": {"model": "random", "diameter": D, "volume_fraction": 0.05,
                        "region": {"box": {"min": [-0.02 + D, -0.02 + D, 0.10], "max": [0.02 - D, 0.0 - D, 0.12]}}},
             "mass_rate": 0.087, "interval": 5e-4}]


def scenario(name, levels):
    top = level(*levels[0])
    top["pour"] = pour()
    doc = {
        "$schema": "../../docs/domel.schema.json",
        "name": name,
        "description": "Bin fill beside LIGGGHTS-PFM's bin_fill example (scenarios/bin_fill/make_bin_fill.py): "
                       + ", ".join(f"{n} (alpha = {a})" for n, a in levels),
        "gravity": [0, 0, -9.81],
        "materials": {"glass": {"density": 2500.0, "youngs_modulus": 1e8, "poisson_ratio": 0.35},
                      "steel": {"youngs_modulus": 1e8, "poisson_ratio": 0.35}},
        "interactions": [{"materials": ["glass", "glass"], "restitution": 0.6, "friction": 0.3},
                         {"materials": ["glass", "steel"], "restitution": 0.6, "friction": 0.5}],
        "walls": [{"name": "bin", "type": "box", "material": "steel", "min": [-0.02, -0.02, -0.02],
                   "max": [0.02, 0.0, 0.125], "open": ["zmax"]}],
        "subdomains": [top] + [level(n, a) for n, a in levels[1:]],
        "run": {"duration": 0.6, "seed": 1},
        "output": {"vtk_interval": 0.05, "probe_interval": 0.005,
                   "grids": [dict(name="window", subdomain=levels[-1][0], every=15, write_interval=0.01, **WINDOW)]},
    }
    if len(levels) > 1:
        doc["couplings"] = [{"name": "coupling", "coarse": levels[0][0], "fine": levels[1][0], "region": WINDOW,
                             "inflow_faces": ["+z", "-z"], "shell_depth": 0.003,
                             "velocity_control": {"enabled": False}, "grid_interval": 0.01}]
    return doc


if __name__ == "__main__":
    for name, levels in (("bin_fill_fine", [("fine", 1)]), ("bin_fill_2lvl", [("coarse", 2), ("fine", 1)])):
        with open(os.path.join(HERE, name + ".json"), "w") as f:
            json.dump(scenario(name, levels), f, indent=2)
            f.write("\n")
        print("wrote", name + ".json")
