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
                    the CI-sized case with the Beverloo check;
and the coupled ones (docs/multilevel.md, docs/validation/multilevel.md):
  silo_2lvl.json    silo_coarse (alpha = 2 everywhere) with a fine level
                    (alpha = 1) in the lower quarter of the bed, around the outlet;
  silo_3lvl.json    alpha = 4 everywhere, alpha = 2 in the lower half, alpha = 1
                    in the lower quarter;
  silo_ci_2lvl.json silo_ci at alpha = 2 with a fine level in its lower half
                    (the CI-sized coupled case), and silo_ci_2lvl_nostress.json
                    the same without the stress controller, and
                    silo_ci_2lvl_nomatch.json without match_outflow;
  silo_2lvl_nostress.json  silo_2lvl without the stress controller (what the
                    transition cells' pressure is without it).
Every variant has a grid "zone" with the fine region's cells, so that the
pressure in the transition cells compares level by level.
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

# The fine regions: the silo's cross-section from 4 cm below the floor (the
# fine particles leave through the region's bottom face, which is the
# discharge) up to z_top; cells of 30 x 30 x 15 mm (full size) or 14 mm (CI),
# at least 2 parcel diameters of the level above.
ZONES = {
    "full": dict(lo=-0.04, top=0.05, cells=(5, 6)),  # the lower quarter of the ~0.20 m bed
    "full_medium": dict(lo=-0.04, top=0.10, cells=(5, 5)),  # the lower half
    "ci": dict(lo=-0.028, top=0.042, cells=(5, 5)),  # the lower half of the ~0.075 m bed
}
MULTILEVEL = {
    # name: base variant, [(alpha, zone or None for everywhere), ...] coarsest first
    "silo_2lvl": ("silo_coarse", [(2, None), (1, "full")]),
    "silo_3lvl": ("silo_coarse", [(4, None), (2, "full_medium"), (1, "full")]),
    "silo_ci_2lvl": ("silo_ci", [(2, None), (1, "ci")]),
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
                       "cells": [cells[0], cells[0], cells[1]], "every": 15, "write_interval": 0.05},
                      zone_grid("zone", R, ZONES["ci" if R < 0.05 else "full"])],
        },
    }
    return doc


def zone_box(R, z):
    return {"min": [-R, -R, z["lo"]], "max": [R, R, z["top"]], "cells": [z["cells"][0], z["cells"][0], z["cells"][1]]}


def zone_grid(name, R, z):
    return dict(name=name, **zone_box(R, z), every=15, write_interval=0.05)


def multilevel(name, base, levels, stress=True, match=True):
    """The base silo at the coarsest level's alpha, plus one finer subdomain
    per further level, each coupled to the one before it on its zone. Every
    zone holds the outlet, so each coupling matches the coarse outflow to the
    fine one (match_outflow, docs/multilevel.md) unless match is False."""
    v = dict(VARIANTS[base])
    v["alpha"] = levels[0][0]
    doc = scenario(name, **v)
    R = v["R"]
    coarse = doc["subdomains"][0]
    coarse["name"] = f"alpha{levels[0][0]}"
    doc["description"] = (f"Multi-level silo (scenarios/silo/make_silo.py): {base} with levels "
                          + ", ".join(f"alpha = {a}" + (f" below z = {ZONES[z]['top']} m" if z else " everywhere")
                                      for a, z in levels) + ", coupled level by level (docs/multilevel.md).")
    doc["couplings"] = []
    for k in range(1, len(levels)):
        alpha, zone = levels[k]
        doc["subdomains"].append({
            "name": f"alpha{alpha}", "material": "glass", "coarse_grain": alpha,
            "contact": coarse["contact"], "time_step": 1.8e-5 * alpha, "impact_velocity": 1.0})
        c = {"name": f"zone{k}", "coarse": f"alpha{levels[k - 1][0]}", "fine": f"alpha{alpha}",
             "region": zone_box(R, ZONES[zone]), "inflow_faces": ["+z"], "match_outflow": match,
             "grid_interval": 0.05}
        if not stress:
            c["stress_control"] = {"enabled": False}
        doc["couplings"].append(c)
    finest = doc["subdomains"][-1]["name"]
    doc["output"]["mass_flow"][0]["subdomain"] = finest  # the discharge at the fine level's outlet
    doc["output"]["grids"][0]["subdomain"] = coarse["name"]
    doc["output"]["grids"][1]["subdomain"] = finest
    return doc


if __name__ == "__main__":
    for name, v in VARIANTS.items():
        with open(os.path.join(HERE, name + ".json"), "w") as f:
            json.dump(scenario(name, **v), f, indent=2)
            f.write("\n")
        print("wrote", name + ".json")
    for name, (base, levels) in MULTILEVEL.items():
        variants = [(name, True, True)]
        if name == "silo_ci_2lvl":
            variants += [(name + "_nostress", False, True), (name + "_nomatch", True, False)]
        elif name == "silo_2lvl":
            variants += [(name + "_nostress", False, True)]
        for out, stress, match in variants:
            with open(os.path.join(HERE, out + ".json"), "w") as f:
                json.dump(multilevel(out, base, levels, stress, match), f, indent=2)
                f.write("\n")
            print("wrote", out + ".json")
