#!/usr/bin/env python3
"""Compares silo runs at one and several levels (docs/validation/multilevel.md).

Usage:
  analyse_multilevel.py [--plot OUT.png] [--fill T0 T1] [--markdown] LABEL=OUTDIR ...

For each run (its output folder, written by `domel run`):
  - discharge: the steady rate of the mass-flow plane `orifice` (summary.json,
    least squares over its rate window; in a coupled run the plane counts the
    finest level only);
  - delivered: for a coupled run, the rate at which the coupling counted coarse
    mass into the finest region (least squares of the +z face's counted mass
    in <coupling>_balance.csv over the same window), and its ratio to the
    discharge (a steady fine region needs 1);
  - transition pressure: the mean pressure of the top layer of the "zone" grid
    (the cells under the inflow face, at the finest level) over the fill
    window T0..T1, from zone_profile.csv;
  - wall time, particles, and whether every level's mass balance is exact.
The first run is the reference for the "vs" columns.
"""
import argparse
import csv
import json
import os
import sys


def slope(ts, vs, t0, t1):
    pts = [(t, v) for t, v in zip(ts, vs) if t0 <= t <= t1]
    if len(pts) < 3:
        return float("nan")
    n = len(pts)
    mt = sum(t for t, _ in pts) / n
    mv = sum(v for _, v in pts) / n
    den = sum((t - mt) ** 2 for t, _ in pts)
    return sum((t - mt) * (v - mv) for t, v in pts) / den


def read_csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return rows


def analyse(out, fill):
    s = json.load(open(os.path.join(out, "summary.json")))
    r = {"wall": s["wall_time_s"], "particles_end": s["particles"]}
    plane = s.get("mass_flow", {}).get("orifice", {})
    steady = plane.get("steady", {})
    r["discharge"] = steady.get("rate_kg_s")
    window = steady.get("window_s", [float("nan"), float("nan")])
    r["exact"] = all(v["exact"] for v in s["mass_balance"].values())
    r["delivered"] = None
    couplings = s.get("couplings", {})
    if couplings:
        finest = list(couplings)[-1]
        rows = read_csv(os.path.join(out, finest + "_balance.csv"))
        ts = [float(x["time"]) for x in rows]
        counted = [float(x["+z.counted_kg"]) for x in rows]
        r["delivered"] = slope(ts, counted, window[0], window[1])
        r["backlog_end"] = couplings[finest]["faces"]["+z"]["backlog"]
        r["pending_kg"] = couplings[finest]["pending_kg"]
    prof = os.path.join(out, "zone_profile.csv")
    r["p_transition"] = None
    if os.path.exists(prof):
        rows = read_csv(prof)
        top = max(int(x["layer"]) for x in rows)
        ps = [float(x["pressure"]) for x in rows if int(x["layer"]) == top and fill[0] <= float(x["time"]) <= fill[1]]
        r["p_transition"] = sum(ps) / len(ps) if ps else None
        r["p_series"] = [(float(x["time"]), float(x["pressure"])) for x in rows if int(x["layer"]) == top]
    probes = read_csv(os.path.join(out, "probes.csv"))
    r["t"] = [float(x["time"]) for x in probes]
    r["m"] = [float(x["orifice.mass_kg"]) for x in probes]
    return r


def pct(a, b):
    if a is None or b is None or b == 0:
        return "—"
    return f"{100 * (a / b - 1):+.1f} %"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--plot")
    ap.add_argument("--fill", nargs=2, type=float, default=[0.2, 0.5])
    a = ap.parse_args()
    res = []
    for spec in a.runs:
        label, out = spec.split("=", 1)
        res.append((label, analyse(out, a.fill)))
    ref = res[0][1]
    print("| case | discharge [kg/s] | vs first | delivered into fine [kg/s] | delivered/discharge | "
          f"p transition {a.fill[0]}-{a.fill[1]} s [Pa] | vs first | wall [s] | vs first | balance |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for label, r in res:
        d, dl, p = r["discharge"], r["delivered"], r["p_transition"]
        d_s = "—" if d is None else f"{d:.4f}"
        dl_s = "—" if dl is None else f"{dl:.4f}"
        ratio_s = "—" if dl is None or not d else f"{dl / d:.3f}"
        p_s = "—" if p is None else f"{p:.0f}"
        print(f"| {label} | {d_s} | {pct(d, ref['discharge'])} | {dl_s} | {ratio_s} | {p_s} | "
              f"{pct(p, ref['p_transition'])} | {r['wall']:.0f} | {r['wall'] / ref['wall']:.2f} | "
              f"{'exact' if r['exact'] else 'NOT exact'} |")
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(1, 2, figsize=(11, 4))
        for label, r in res:
            ax[0].plot(r["t"], r["m"], label=label)
            if r.get("p_series"):
                ax[1].plot(*zip(*r["p_series"]), label=label)
        ax[0].set_xlabel("t [s]")
        ax[0].set_ylabel("mass through the orifice plane [kg]")
        ax[1].set_xlabel("t [s]")
        ax[1].set_ylabel("pressure, top layer of the fine zone [Pa]")
        for x in ax:
            x.legend(fontsize=8)
            x.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=110)
        print("wrote", a.plot, file=sys.stderr)


if __name__ == "__main__":
    main()
