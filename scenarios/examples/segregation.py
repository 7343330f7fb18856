#!/usr/bin/python3
"""Segregation index over time of a vibrated binary mixture (scenarios/examples/shaker.json).

Reads <folder>/probes.csv of each run folder given: the centres of mass of the two components
(output.region_mass "large" and "small" with centre_of_mass) and computes

    S(t) = (z_large(t) - z_small(t)) / h0,

h0 the mean height of the bed's centre of mass over the 0.2 s before the shaking starts (--start, default 0.5 s):
0 for a mixed bed, 1 for a 50/50 (by volume) bed fully segregated with the large beads on top, -1 the reverse.
Prints S averaged over consecutive windows (--window, default 0.5 s); with --plot PNG draws S(t) for every
folder (needs matplotlib: python3-matplotlib).

Usage:
    scenarios/examples/segregation.py OUT [OUT ...] [--plot segregation.png] [--labels A B ...]
Exit status: 0, or 2 when a folder lacks the columns.
"""

import argparse
import csv
import os
import sys


def index(folder, start):
    path = os.path.join(folder, "probes.csv")
    if not os.path.exists(path):
        sys.exit(f"segregation: {path} not found")
    with open(path) as f:
        rows = list(csv.DictReader(f))
    if not rows or "large.com_z" not in rows[0] or "small.com_z" not in rows[0]:
        sys.exit(f"segregation: {path} lacks large.com_z / small.com_z (output.region_mass with centre_of_mass)")
    t = [float(r["time"]) for r in rows]
    zl = [float(r["large.com_z"]) for r in rows]
    zs = [float(r["small.com_z"]) for r in rows]
    ml = [float(r["large.mass_kg"]) for r in rows]
    ms = [float(r["small.mass_kg"]) for r in rows]
    rest = [(a * ma + b * mb) / (ma + mb) for tk, a, b, ma, mb in zip(t, zl, zs, ml, ms) if start - 0.2 < tk <= start]
    h0 = sum(rest) / len(rest)
    return t, [(a - b) / h0 for a, b in zip(zl, zs)], h0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folders", nargs="+")
    ap.add_argument("--start", type=float, default=0.5, help="time the shaking starts [s] (default 0.5)")
    ap.add_argument("--window", type=float, default=0.5, help="averaging window for the table [s] (default 0.5)")
    ap.add_argument("--plot", help="write S(t) to this PNG")
    ap.add_argument("--labels", nargs="+", help="legend entries, one per folder (default: the folders' names)")
    a = ap.parse_args()
    series = []
    for folder in a.folders:
        t, s, h0 = index(folder, a.start)
        series.append((folder, t, s))
        print(f"{folder}: h0 = {h0 * 1e3:.2f} mm")
        w0 = 0.0
        while w0 < t[-1] - 1e-9:
            sel = [sk for tk, sk in zip(t, s) if w0 < tk <= w0 + a.window + 1e-9]
            if sel:
                print(f"  {w0:5.2f}-{w0 + a.window:5.2f} s: S = {sum(sel) / len(sel):+.3f}")
            w0 += a.window
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 3.8))
        labels = a.labels or [os.path.basename(os.path.normpath(f)) for f, _, _ in series]
        for (folder, t, s), label in zip(series, labels):
            ax.plot(t, s, lw=1, label=label)
        ax.axvline(a.start, color="grey", lw=0.8, ls=":")
        ax.axhline(0, color="grey", lw=0.8)
        ax.set_xlabel("t [s]")
        ax.set_ylabel("S = (z_large - z_small) / h0")
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=120)
        print(f"wrote {a.plot}")


if __name__ == "__main__":
    main()
