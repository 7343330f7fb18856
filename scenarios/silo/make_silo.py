#!/usr/bin/env python3
"""Writes the silo discharge scenarios (issue 4; shared physics.md §5.7, §6.1):
a flat-bottomed cylindrical silo with a central round outlet, filled by
pouring d = 2.8 mm glass spheres (S1 material: rho 2500 kg/m^3, E 5 MPa,
nu 0.3, e 0.5, mu 0.5 particle-particle and particle-wall, no rolling
resistance), settled with the outlet plugged, then discharged into a
deletion region that counts the mass. Variants:
  silo_fine.json    D = 150 mm, outlet 30 mm (10.7 d), 187,504 particles as in
                    the mission's reference (5.39 kg), alpha = 1;
  silo_coarse.json  the same silo and mass at alpha = 2: 23,438 parcels of
                    5.6 mm (the mission's coarse-only case);
  silo_ci.json      D = 70 mm, outlet 20 mm (7.1 d), 15,000 particles, alpha = 1:
                    the CI-sized case with the Beverloo check.
Each pours at a mass rate from a cylinder near the top (random sequential
addition at volume fraction 0.22, 1.5 m/s downwards; RSA in a
narrow cylinder jams well below its bulk limit of 0.38), opens the outlet once
the bed has settled, and reports the steady discharge rate (least squares
over rate_window) in summary.json; a cell grid gives the volume fraction and
the pressure profile over height. Time step 1.8e-5 s: 21 steps per contact
at 1 m/s (the estimator's contact time 3.8e-4 s), below the stability limit.
Usage: make_silo.py"""
import json, math, os

HERE = os.path.dirname(os.path.abspath(__file__))
D_P = 0.0028
RHO = 2500.0
M_P = RHO * math.pi / 6 * D_P ** 3

VARIANTS = {
    # name: silo radius, outlet diameter, particles (alpha = 1 count), alpha, top, pour [z0, z1], rate kg/s,
    #       open time, end time, fit window start, grid cells (xy, z), vtk interval
    "silo_fine": dict(R=0.075, Do=0.030, n=187504, alpha=1, top=0.33, pour=(0.26, 0.32), rate=10.0,
                      t_open=1.0, t_end=2.5, fit0=1.3, cells=(5, 24), grid_top=0.24, vtk=0.1),
    "silo_coarse": dict(R=0.075, Do=0.030, n=187504, alpha=2, top=0.33, pour=(0.26, 0.32), rate=10.0,
                        t_open=1.0, t_end=2.5, fit0=1.3, cells=(5, 24), grid_top=0.24, vtk=0.1),
    "silo_ci": dict(R=0.035, Do=0.020, n=15000, alpha=1, top=0.17, pour=(0.10, 0.16), rate=2.5,
                    t_open=0.5, t_end=1.15, fit0=0.65, cells=(2, 8), grid_top=0.08, vtk=0.05),
}


def scenario(name, R, Do, n, alpha, top, pour, rate, t_open, t_end, fit0, cells, grid_top, vtk):
    mass = n * M_P  # equal mass for every alpha: n / alpha^3 parcels
    dt = 1.8e-5 * alpha  # the contact time scales with alpha (docs/physics.md, coarse graining)
    doc = {
        "$schema": "../../docs/domel.schema.json",
        "name": name,
        "description": (f"Silo discharge (scenarios/silo/make_silo.py): cylinder D = {2 * R * 1e3:.0f} mm, "
                        f"flat bottom with a {Do * 1e3:.0f} mm outlet opened at {t_open} s, {mass:.3f} kg of "
                        f"d = 2.8 mm glass spheres at coarse-grain ratio {alpha} "
                        f"({round(n / alpha ** 3)} {'parcels' if alpha > 1 else 'particles'}), poured at {rate} kg/s."),
        "gravity": [0, 0, -9.81],
        "materials": {
            "glass": {"density": RHO, "youngs_modulus": 5e6, "poisson_ratio": 0.3},
            "steel": {"youngs_modulus": 5e6, "poisson_ratio": 0.3},
        },
        "interactions": [
            {"materials": ["glass", "glass"], "restitution": 0.5, "friction": 0.5},
            {"materials": ["glass", "steel"], "restitution": 0.5, "friction": 0.5},
        ],
        "walls": [
            {"name": "silo", "type": "cylinder", "material": "steel", "axis": "z", "center": [0, 0, 0],
             "radius": R, "bottom": 0.0, "top": top, "closed_bottom": True, "outlet_radius": Do / 2,
             "outlet_open_at": t_open},
        ],
        "deletion_regions": [
            {"name": "outlet", "region": {"cylinder": {"axis": "z", "center": [0, 0, 0], "radius": 2 * R,
                                                       "bottom": -1.0, "top": -0.05}},
             "rate_window": [fit0, t_end]},
        ],
        "subdomains": [{
            "name": "grains", "material": "glass", "coarse_grain": alpha,
            "contact": {"normal": {"model": "hertz"}, "damping": {"model": "restitution"},
                        "tangential": {"model": "mindlin"}},
            "time_step": dt, "impact_velocity": 1.0,
            "pour": [{
                "insert": {"model": "random", "diameter": D_P, "volume_fraction": 0.22,
                           "region": {"cylinder": {"axis": "z", "center": [0, 0, 0],
                                                   "radius": R - alpha * D_P, "bottom": pour[0], "top": pour[1]}},
                           "velocity": [0, 0, -1.5]},
                "mass_rate": rate, "total_mass": mass,
            }],
        }],
        "run": {"duration": t_end, "seed": 1},
        "output": {
            "vtk_interval": vtk, "probe_interval": 0.01,
            "mass_flow": [{"name": "orifice", "point": [0, 0, -0.01], "normal": [0, 0, -1],
                           "rate_window": [fit0, t_end]}],
            "grids": [{"name": "bed", "min": [-R, -R, 0.0], "max": [R, R, grid_top],
                       "cells": [cells[0], cells[0], cells[1]], "every": 15, "write_interval": 0.05}],
        },
    }
    return doc


if __name__ == "__main__":
    for name, v in VARIANTS.items():
        with open(os.path.join(HERE, name + ".json"), "w") as f:
            json.dump(scenario(name, **v), f, indent=2)
            f.write("\n")
        print("wrote", name + ".json")
