#!/usr/bin/env python3
"""Cost of the built-in fluid coupler's step per cell at three grid sizes
(issue 16 item 6; docs/performance.md, "Fluid step"). Air enters a
40 x 40 x 200 mm chamber from below at 1.5 m/s and flows round a plate of
23 mm diameter 140 mm up (the chamber case's geometry, without particles),
one fluid step of 40 us per exchange (the advective limit of the finest
grid round the plate is about 80 us). For each grid the run does 20 exchanges; the
coupler's own time (summary.json fluid.coupler_seconds: predictor, pressure
assembly and solve, correction) is divided by the exchanges and the cells,
and the last pressure solve's iterations are printed. A multigrid solve
keeps the time per cell about constant as the grid grows; a preconditioned
conjugate gradient does not (its iterations grow with the grid's width).
Both pressure solves are measured ("solver": {"backend": "cg" | "pfmg"}).
Usage: bench/fluid_solve.py [--domel build/bin/domel] [--reps 3] [--backends cg,pfmg]"""
import argparse, json, os, shutil, statistics, subprocess, sys, tempfile

GRIDS = [(8, 8, 40), (16, 16, 80), (32, 32, 160)]


def deck(cells, backend):
    return {
        "name": "fluid_solve_bench",
        "gravity": [0, 0, -9.81],
        "materials": {"glass": {"density": 2500, "youngs_modulus": 1e7, "poisson_ratio": 0.3}},
        "interactions": [{"materials": ["glass", "glass"], "restitution": 0.9, "friction": 0.3}],
        "subdomains": [{"name": "none", "material": "glass", "time_step": 1e-5}],
        "fluid": {"model": "vans", "interval": 4e-5,
                  "grid": {"min": [0, 0, 0], "max": [0.04, 0.04, 0.2], "cells": list(cells)},
                  "density": 1.2, "viscosity": 1.8e-5,
                  "boundaries": {"z_min": {"type": "velocity_inlet", "velocity": [0, 0, 1.5]},
                                 "z_max": {"type": "pressure_outlet"}},
                  "obstacles": [{"cylinder": {"axis": "z", "center": [0.02, 0.02], "radius": 0.0115,
                                              "min": 0.139, "max": 0.141}}],
                  "initial_velocity": [0, 0, 1.5], "write_interval": 0,
                  "solver": {"backend": backend}},
        "run": {"steps": 80},
        "output": {"vtk_interval": 0, "probe_interval": 0}}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--domel", default="build/bin/domel")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--backends", default="cg,pfmg", help="comma-separated: cg, pfmg")
    args = ap.parse_args()
    print("| solve | grid | cells | fluid step per exchange [ms] (median of %d) | per cell [us] | last solve's iterations |" % args.reps)
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
      for backend in args.backends.split(","):
        for cells in GRIDS:
            n = cells[0] * cells[1] * cells[2]
            f = os.path.join(tmp, "deck.json")
            json.dump(deck(cells, backend), open(f, "w"))
            times, iters = [], 0
            for r in range(args.reps):
                out = os.path.join(tmp, "out")
                shutil.rmtree(out, ignore_errors=True)  # domel refuses a folder with an earlier run's output
                subprocess.run([args.domel, "run", f, "--out", out, "--quiet", "--threads", "1"], check=True,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                fl = json.load(open(os.path.join(out, "summary.json")))["fluid"]
                times.append(fl["coupler_seconds"] / fl["exchanges"])
                iters = fl["limits"]["solver_iterations"]
            t = statistics.median(times)
            print(f"| {backend} | {cells[0]} x {cells[1]} x {cells[2]} | {n} | {1e3 * t:.2f} | {1e6 * t / n:.2f} | {iters} |")
            sys.stdout.flush()


if __name__ == "__main__":
    main()
