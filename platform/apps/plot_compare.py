#!/usr/bin/env python3
"""Plots for `domel compare` (written next to the report and run by domel):
one PNG per observable, one line per variant, from each variant's
probes.csv. Usage: plot_compare.py OUTDIR LABEL DIR [LABEL DIR ...]"""
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

PLOTS = [  # (column suffix, title, y label, log scale)
    ("median_angular_speed", "Median |omega| of the particles", "median |omega| [rad/s]", True),
    ("trimmed_mean_angular_speed", "Mean |omega| of particles below 1 rad/s", "mean |omega| [rad/s]", True),
    ("ke_translational", "Translational kinetic energy", "E_kin [J]", True),
    ("ke_rotational", "Rotational kinetic energy", "E_rot [J]", True),
    ("repose_angle_deg", "Angle of repose (free-surface fit)", "angle [deg]", False),
]
# One PNG per column name: NAME.SUFFIX.png (output.region_mass, deletion regions).
PER_COLUMN = [  # (column suffix, title, y label)
    ("mass_kg", "Mass in region (or crossed plane) {name}", "mass [kg]"),
    ("removed_kg", "Mass removed by {name}", "mass [kg]"),
]


def read(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return rows


def save(fig, ax, out, name, title, ylabel, log):
    """Labels, legend and PNG of one plot; returns the file name."""
    if log:
        ax.set_yscale("log")
    ax.set_xlabel("simulated time [s]")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, name), dpi=110)
    plt.close(fig)
    return name


def main():
    out = sys.argv[1]
    args = sys.argv[2:]
    variants = list(zip(args[0::2], args[1::2]))
    data = {label: read(os.path.join(d, "probes.csv")) for label, d in variants}
    written = []
    for suffix, title, ylabel, log in PLOTS:
        fig, ax = plt.subplots(figsize=(7, 4.2))
        drawn = False
        for label, rows in data.items():
            cols = [c for c in (rows[0].keys() if rows else []) if c.endswith("." + suffix)]
            for col in cols:
                t, y = [], []
                for r in rows:
                    v = float(r[col])
                    if math.isfinite(v) and (v > 0 or not log):
                        t.append(float(r["time"]))
                        y.append(v)
                if t:
                    name = label if len(cols) == 1 else f"{label} ({col.split('.')[0]})"
                    ax.plot(t, y, label=name, linewidth=1.4)
                    drawn = True
        if not drawn:
            plt.close(fig)
            continue
        written.append(save(fig, ax, out, f"{suffix}.png", title, ylabel, log))
    names = sorted({c for rows in data.values() for c in (rows[0].keys() if rows else [])})
    for suffix, title, ylabel in PER_COLUMN:
        for col in [c for c in names if c.endswith("." + suffix)]:
            fig, ax = plt.subplots(figsize=(7, 4.2))
            drawn = False
            for label, rows in data.items():
                if not rows or col not in rows[0]:
                    continue
                pts = [(float(r["time"]), float(r[col])) for r in rows if math.isfinite(float(r[col]))]
                if pts:
                    ax.plot([p[0] for p in pts], [p[1] for p in pts], label=label, linewidth=1.4)
                    drawn = True
            if not drawn:
                plt.close(fig)
                continue
            written.append(save(fig, ax, out, f"{col}.png", title.format(name=col[: -len(suffix) - 1]), ylabel, False))
    print("\n".join(written))


if __name__ == "__main__":
    main()
