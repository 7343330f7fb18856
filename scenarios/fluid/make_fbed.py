#!/usr/bin/env python3
"""Writes the gas-fluidised bed scenarios of docs/validation/fluid.md,
cases (c) and (d), into scenarios/fluid/bed/:

  mf_uNNN.json   case (c), minimum fluidisation: 1 mm glass beads, a bed
                 about 12 cells of 3 mm tall in a 12 x 12 mm column (4 x 4
                 cells), at the superficial velocity NNN/100 m/s; the
                 Gidaspow law. The pressure drop against U gives U_mf, the
                 bed's height below U_mf gives eps_mf.
  a{1,2,4}.json  case (d), the same bed at coarse-grain ratio 1, 2 and 4:
                 39,616 beads of 1 mm (619 parcels at alpha = 4, 4952 at
                 alpha = 2), a 24 x 24 mm column of 2 x 2 cells of 12 mm
                 (3 parcel diameters at alpha = 4), the bed about 5 cells
                 tall, fluidised at U_D m/s; the Gidaspow law with
                 coarse-grain scaling.
  a{2,4}_unscaled.json  the same without drag scaling (a parcel feels the
                 drag of one sphere of its own size).
  a{1,2,4}_wide.json  the same in a column twice as wide (48 x 48 mm, 4 x 4
                 cells) with four times the beads (158,464 at alpha = 1): is
                 a difference between the ratios the narrow column's (6
                 parcels across at alpha = 4)?
  a{1,2,4}_c24.json  the beds of a{1,2,4}.json on cells of 24 mm (1 x 1 x 10:
                 6 parcel diameters at alpha = 4, against 3 on the 12 mm
                 cells) for 3 s: on 12 mm cells the alpha = 4 bed expands
                 less than alpha = 1 and 2 whatever the walls, drag law and
                 collision parameters; is it the cells' size against the
                 parcels'? a{2,4}_c24_unscaled.json: the same without drag
                 scaling, 0.8 s.
  w{1,2,4}.json  the beds of a{1,2,4}.json fluidised by water at U_W m/s
                 instead of air, for 2 s: a liquid-fluidised bed of these
                 beads expands homogeneously (no bubbles, no slugs), so its
                 height is one number to compare across alpha and with the
                 drag law's own equilibrium.

Every bed is a loose jittered lattice dropped at t = 0 into the rising gas;
it settles in about 0.2 s. The columns' walls are frictionless for the
beads (a wall's friction would carry part of the bed's weight) and slip
walls for the gas. The bed lies on the fluid's inlet face (no plenum): the
void-fraction kernel is clamped there and does not smear the bed's bottom.
Usage: make_fbed.py [OUTDIR] (default: bed/ beside this script)."""
import json
import math
import os
import sys

D = 1e-3             # bead diameter [m]
RHO = 2500.0         # glass [kg/m^3]
E = 5e6              # Young's modulus [Pa]: S1's material (docs/validation/fluid.md says why)
RHO_F, MU_F = 1.2, 1.8e-5   # air
RHO_W, MU_W = 1000.0, 1e-3  # water
U_W = 0.04           # the water beds: about 5 U_mf (Wen-Yu: 8 mm/s), a third of the beads' terminal velocity [m/s]
U_MF_SWEEP = [0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 1.0]   # case (c) [m/s]
U_D = 1.2            # case (d): about twice U_mf [m/s]
N_D = 39616          # case (d): beads at alpha = 1 (= 619 x 4^3)
DT = 5e-6            # DEM step of a 1 mm bead [s]: its Hertz contact time at 1 m/s over 27 (a bed's
                     # collisions are slower, their contacts longer); a parcel's is alpha times longer


def scenario(name, description, side, cells_xy, cell_z, height, alpha, count, u, duration,
             scaling=True, write_interval=0.01, vtk_interval=0.02, rho_f=RHO_F, mu_f=MU_F):
    spacing = 1.1
    a = spacing * D * alpha
    return {
        "$schema": "../../../docs/domel.schema.json",
        "name": name,
        "description": description + " Written by scenarios/fluid/make_fbed.py; docs/validation/fluid.md.",
        "gravity": [0, 0, -9.81],
        "materials": {"glass": {"density": RHO, "youngs_modulus": E, "poisson_ratio": 0.3},
                      "wall": {"density": RHO, "youngs_modulus": E, "poisson_ratio": 0.3}},
        "interactions": [
            {"materials": ["glass", "glass"], "restitution": 0.9, "friction": 0.3},
            {"materials": ["glass", "wall"], "restitution": 0.9, "friction": 0.0}],
        "walls": [{"name": "column", "type": "box", "material": "wall", "min": [0, 0, 0],
                   "max": [side, side, height], "open": []}],
        "subdomains": [{
            "name": "beads", "material": "glass", "coarse_grain": alpha, "time_step": DT * alpha,
            "contact": {"normal": {"model": "hertz"}, "damping": {"model": "restitution"},
                        "tangential": {"model": "mindlin"}},
            "insert": [{"model": "lattice", "diameter": D, "spacing": spacing, "jitter": 0.04, "count": count,
                        "region": {"box": {"min": [0, 0, 0], "max": [side, side, height - a]}}}]}],
        "fluid": {
            "model": "vans", "interval": 1e-4,
            "grid": {"min": [0, 0, 0], "max": [side, side, height],
                     "cells": [cells_xy, cells_xy, int(round(height / cell_z))]},
            "density": rho_f, "viscosity": mu_f,
            "drag": {"law": "gidaspow", "coarse_grain_scaling": scaling},
            "boundaries": {s: {"type": "slip_wall"} for s in ("x_min", "x_max", "y_min", "y_max")} | {
                "z_min": {"type": "velocity_inlet", "velocity": [0, 0, u]},
                "z_max": {"type": "pressure_outlet"}},
            "initial_velocity": [0, 0, u],
            "write_interval": write_interval},
        "run": {"duration": duration, "seed": 1},
        "output": {"vtk_interval": vtk_interval, "probe_interval": 0.01, "state": True},
    }


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "bed")
    os.makedirs(out, exist_ok=True)
    docs = {}
    # (c): 12 x 12 mm, 4 x 4 x 40 cells of 3 mm; 5940 beads fill about 36 mm at eps 0.4
    for u in U_MF_SWEEP:
        name = f"mf_u{round(100 * u):03d}"
        docs[name] = scenario(
            name, f"Fluidised bed, case (c): 5940 glass beads of 1 mm in a 12 x 12 mm column, 3 mm cells, "
            f"air at {u} m/s, Gidaspow drag.", 0.012, 4, 0.003, 0.12, 1, 5940, u, 0.6)
    # (d): 24 x 24 mm, 2 x 2 x 20 cells of 12 mm; the same mass at alpha = 1, 2, 4
    def ratios(suffix, case, cells_xy, cell_z, cells_text, duration):
        """a{1,2,4}<suffix> with drag scaling, a{2,4}<suffix>_unscaled without it (0.8 s)."""
        for alpha in (1, 2, 4):
            for scaling in (True, False):
                if alpha == 1 and not scaling:
                    continue
                name = f"a{alpha}{suffix}" + ("" if scaling else "_unscaled")
                count = N_D // alpha ** 3
                docs[name] = scenario(
                    name, f"Fluidised bed, case (d){case}: {N_D} glass beads of 1 mm as {count} parcels of "
                    f"alpha = {alpha}, 24 x 24 mm column, {cells_text}, air at {U_D} m/s, Gidaspow drag"
                    + ("" if scaling else ", coarse-grain drag scaling OFF") + ".",
                    0.024, cells_xy, cell_z, 0.24, alpha, count, U_D, duration if scaling else 0.8, scaling)
    ratios("", "", 2, 0.012, "12 mm cells", 0.8)
    for alpha in (1, 2, 4):
        name = f"a{alpha}_wide"
        count = 4 * N_D // alpha ** 3
        docs[name] = scenario(
            name, f"Fluidised bed, case (d), twice as wide: {4 * N_D} glass beads of 1 mm as {count} parcels of "
            f"alpha = {alpha}, 48 x 48 mm column, 12 mm cells, air at {U_D} m/s, Gidaspow drag.",
            0.048, 4, 0.012, 0.24, alpha, count, U_D, 0.8)
    ratios("_c24", ", on larger cells", 1, 0.024, "one column of 24 mm cells", 3.0)
    for alpha in (1, 2, 4):
        name = f"w{alpha}"
        count = N_D // alpha ** 3
        docs[name] = scenario(
            name, f"Liquid-fluidised bed, case (d): {N_D} glass beads of 1 mm as {count} parcels of alpha = {alpha}, "
            f"24 x 24 mm column, 12 mm cells, water at {U_W} m/s, Gidaspow drag.",
            0.024, 2, 0.012, 0.24, alpha, count, U_W, 2.0, rho_f=RHO_W, mu_f=MU_W)
    for name, doc in docs.items():
        with open(os.path.join(out, name + ".json"), "w") as f:
            json.dump(doc, f, indent=1)
            f.write("\n")
        print(os.path.join(out, name + ".json"))


if __name__ == "__main__":
    main()
