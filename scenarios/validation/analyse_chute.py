#!/usr/bin/python3
"""Velocity profiles of chute runs (scenarios/validation/chute.json) and their Bagnold fit.

Reads <folder>/profile_profile.csv of each run folder given, averages every layer's velocity and volume fraction
over the last --window seconds of grid files, finds the free surface H (where the volume fraction falls through
half its bulk value), fits v = c0 + c1 (H - z)^beta over the bulk layers (2.5 d above the base to 1.5 d below H;
beta scanned in steps of 0.01) and prints, per run, H, the surface velocity, the best beta and the fit's rms with
beta = 1.5 (Bagnold; Silbert et al. 2001) and with beta = 1 (a linear profile). With two runs it prints the
largest bulk-layer difference as a share of the first run's surface velocity. With --plot PNG it draws the
profiles (z/d against v) and the beta = 1.5 fit of the first run (needs matplotlib: python3-matplotlib).

Usage:
    scenarios/validation/analyse_chute.py OUT_10D OUT_20D [--window 1.0] [--plot docs/validation/chute_profile.png]
Exit status: 0, or 2 when a folder has no profile.
"""

import argparse
import csv
import os
import sys

D = 2.8e-3  # the beads' diameter in chute.json


def profile(folder, window):
    path = os.path.join(folder, "profile_profile.csv")
    if not os.path.exists(path):
        sys.exit(f"analyse_chute: {path} not found (run scenarios/validation/chute.json with output into {folder})")
    with open(path) as f:
        rows = list(csv.DictReader(f))
    t_end = max(float(r["time"]) for r in rows)
    acc = {}
    for r in rows:
        if float(r["time"]) <= t_end - window + 1e-9:
            continue
        a = acc.setdefault(int(r["layer"]), [float(r["centre"]), 0.0, 0.0, 0])
        a[1] += float(r["vx"])
        a[2] += float(r["volume_fraction"])
        a[3] += 1
    layers = sorted(acc)
    return ([acc[k][0] for k in layers], [acc[k][1] / acc[k][3] for k in layers], [acc[k][2] / acc[k][3] for k in layers])


def surface(z, phi):
    bulk = sum(phi[2:8]) / 6
    for k in range(3, len(z)):
        if phi[k] < 0.5 * bulk:
            return z[k - 1] + (z[k] - z[k - 1]) * (phi[k - 1] - 0.5 * bulk) / (phi[k - 1] - phi[k])
    return z[-1]


def fit(z, v, H, beta):
    pts = [((H - zk) ** beta, vk) for zk, vk in zip(z, v) if 2.5 * D < zk < H - 1.5 * D]
    n = len(pts)
    sx = sum(x for x, _ in pts)
    sy = sum(y for _, y in pts)
    sxx = sum(x * x for x, _ in pts)
    sxy = sum(x * y for x, y in pts)
    c1 = (n * sxy - sx * sy) / (n * sxx - sx * sx)
    c0 = (sy - c1 * sx) / n
    rms = (sum((c0 + c1 * x - y) ** 2 for x, y in pts) / n) ** 0.5
    return c0, c1, rms


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folders", nargs="+")
    ap.add_argument("--window", type=float, default=1.0, help="seconds at the end of the run to average (default 1)")
    ap.add_argument("--plot", help="write the profiles to this PNG")
    ap.add_argument("--title", default="", help="the plot's title")
    a = ap.parse_args()
    runs = []
    for folder in a.folders:
        z, v, phi = profile(folder, a.window)
        H = surface(z, phi)
        betas = [0.8 + 0.01 * k for k in range(170)]
        best = min(betas, key=lambda b: fit(z, v, H, b)[2])
        print(f"{folder}: H = {H / D:.2f} d, surface velocity {max(v):.3f} m/s, best beta {best:.2f} "
              f"(rms {fit(z, v, H, best)[2]:.4f} m/s), beta 1.5 rms {fit(z, v, H, 1.5)[2]:.4f}, "
              f"linear rms {fit(z, v, H, 1.0)[2]:.4f}")
        runs.append((folder, z, v, H, phi))
    if len(runs) == 2:
        (_, za, va, Ha, _), (_, zb, vb, Hb, _) = runs
        bulk = [k for k in range(min(len(za), len(zb))) if 2.5 * D < za[k] < min(Ha, Hb) - 1.5 * D]
        worst = max(abs(va[k] - vb[k]) for k in bulk) / max(va)
        print(f"largest bulk-layer difference: {100 * worst:.1f} % of the surface velocity over {len(bulk)} layers")
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(5, 4.5))
        for (folder, z, v, H, phi), mark in zip(runs, "os^d"):
            filled = [k for k in range(len(z)) if phi[k] > 0.02]  # layers above the surface hold nothing
            ax.plot([v[k] for k in filled], [z[k] / D for k in filled], mark, mfc="none",
                    label=os.path.basename(os.path.normpath(folder)))
        _, z, v, H, _ = runs[0]
        c0, c1, _ = fit(z, v, H, 1.5)
        zs = [2.5 * D + k * (H - 4.0 * D) / 50 for k in range(51)]
        ax.plot([c0 + c1 * (H - zk) ** 1.5 for zk in zs], [zk / D for zk in zs], "k-", lw=1,
                label="Bagnold: v_s - c (H - z)^1.5")
        ax.set_xlabel("v_x [m/s]")
        ax.set_ylabel("z / d")
        if a.title:
            ax.set_title(a.title, fontsize=9)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=120)
        print(f"wrote {a.plot}")


if __name__ == "__main__":
    main()
