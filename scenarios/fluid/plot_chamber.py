#!/usr/bin/env python3
"""Pictures and a table for the DEM-CFD chamber runs (docs/validation/chamber.md).

  plot_chamber.py fields RUN_DIR TIME OUT.png   the gas speed on the chamber's
      mid-plane (y = 20 mm) with its in-plane velocity as arrows and the
      particles within one fluid cell of that plane, over the whole chamber
      and zoomed on the plate
  plot_chamber.py profile OUT.png LABEL=RUN_DIR ...   the heap's surface on the
      plate at the end of each run: the highest particle top over the plate
      in rings of half a parcel diameter, against the distance from the axis
  plot_chamber.py table LABEL=RUN_DIR ...       one Markdown row per run: the
      mass at rest on the plate at the end and averaged over the last 0.2 s,
      its particles, the mass carried out at the top, the largest overlap
      seen, the angle of repose (when a heap can be fitted), the wall time
      and the fluid coupler's share of it (issue 16 item 6)
  plot_chamber.py heaps RUNS_DIR   the heap runs of issue 45 items 3 and 4
      (RUNS_DIR/{heap,still}_a<alpha>_{none,sd}_s<seed>, as run_chamber.sh
      heaps leaves them): per feed, rolling model and alpha the angle on the
      plate at the end of each seed, their mean and spread, the probe's
      resolution (one parcel layer over the plate's radius, atan(alpha d / R)),
      the mass at rest per seed; then, per feed, the paper's claim read off
      the means: S-D within 10 % of its alpha = 4 angle at every alpha, and
      'none' falling from alpha = 4 to 8 by more than the resolution

Reads only domel's own files (fluid_*.vti, particles_*.vtp, *.pvd,
probes.csv, summary.json) with vti.py, without the VTK Python package."""
import csv
import json
import math
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vti import read_vti, read_vtp  # noqa: E402

PLATE_Z, PLATE_R, SIDE = 0.140, 0.0115, 0.04


def frame_at(run, series, t):
    """The file of a .pvd series whose time is nearest to t."""
    text = open(os.path.join(run, series + ".pvd")).read()
    frames = [(float(m.group(1)), m.group(2)) for m in re.finditer(r'timestep="([^"]+)"[^>]*file="([^"]+)"', text)]
    ts, f = min(frames, key=lambda x: abs(x[0] - t))
    return ts, os.path.join(run, f)


def fields(run, t, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    tf, vti = frame_at(run, "fluid", t)
    tp, vtp = frame_at(run, "particles", t)
    (nx, ny, nz), origin, h, a = read_vti(vti)
    u, blocked = a["velocity"], a["blocked"]
    j0, j1 = ny // 2 - 1, ny // 2  # the two cell rows either side of y = 20 mm
    speed = [[0.0] * nx for _ in range(nz)]
    ux = [[0.0] * nx for _ in range(nz)]
    uz = [[0.0] * nx for _ in range(nz)]
    for k in range(nz):
        for i in range(nx):
            c0, c1 = i + nx * (j0 + ny * k), i + nx * (j1 + ny * k)
            if blocked[c0] > 0.5 and blocked[c1] > 0.5:
                speed[k][i] = float("nan")
                continue
            vx, vz = 0.5 * (u[c0][0] + u[c1][0]), 0.5 * (u[c0][2] + u[c1][2])
            ux[k][i], uz[k][i] = vx, vz
            speed[k][i] = math.hypot(vx, vz)
    p = read_vtp(vtp)
    px, pz = [], []
    for (x, y, z) in p["Points"]:
        if abs(y - SIDE / 2) < h[1]:
            px.append(x * 1e3)
            pz.append(z * 1e3)
    ext = [origin[0] * 1e3, (origin[0] + nx * h[0]) * 1e3, origin[2] * 1e3, (origin[2] + nz * h[2]) * 1e3]
    fig, axes = plt.subplots(1, 2, figsize=(9, 7.5), gridspec_kw={"width_ratios": [1, 1.6]})
    for ax, zoom in zip(axes, (False, True)):
        im = ax.imshow(speed, origin="lower", extent=ext, cmap="viridis", vmin=0, vmax=3.0, aspect="equal")
        xs = [(origin[0] + (i + 0.5) * h[0]) * 1e3 for i in range(nx)]
        zs = [(origin[2] + (k + 0.5) * h[2]) * 1e3 for k in range(nz)]
        step = 1 if zoom else 2
        kk = [k for k in range(0, nz, step) if not zoom or 120 <= zs[k] <= 180]
        ax.quiver([xs[i] for k in kk for i in range(0, nx, step)], [zs[k] for k in kk for i in range(0, nx, step)],
                  [ux[k][i] for k in kk for i in range(0, nx, step)], [uz[k][i] for k in kk for i in range(0, nx, step)],
                  color="white", scale=40 if zoom else 60, width=0.004)
        ax.scatter(px, pz, s=2 if not zoom else 6, c="tab:red", linewidths=0)
        ax.plot([(SIDE / 2 - PLATE_R) * 1e3, (SIDE / 2 + PLATE_R) * 1e3], [PLATE_Z * 1e3] * 2, color="k", lw=2.5)
        ax.set_xlabel("x [mm]")
        if zoom:
            ax.set_ylim(120, 180)
            ax.set_title("near the plate")
        else:
            ax.set_ylabel("z [mm]")
            ax.set_title("whole chamber")
    fig.colorbar(im, ax=axes, label="gas speed in the plane [m/s]", shrink=0.8)
    fig.suptitle(f"{os.path.basename(os.path.normpath(run))}: mid-plane y = 20 mm, gas at t = {tf:.2f} s, "
                 f"particles within {h[1] * 1e3:.1f} mm of the plane at t = {tp:.2f} s", fontsize=9)
    fig.savefig(out, dpi=110)
    print(out)


def profile(out, pairs):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for pair in pairs:
        label, run = pair.split("=", 1)
        rows = list(csv.DictReader(open(os.path.join(run, "probes.csv"))))
        _, vtp = frame_at(run, "particles", float(rows[-1]["time"]))
        p = read_vtp(vtp)
        d = 2 * max(p["radius"]) if p["radius"] else 0
        top = {}
        for (x, y, z), r, v in zip(p["Points"], p["radius"], p["velocity"]):
            rr = math.hypot(x - SIDE / 2, y - SIDE / 2)
            if rr > PLATE_R + r or z < PLATE_Z or z > PLATE_Z + 0.01 or math.sqrt(sum(c * c for c in v)) > 0.05:
                continue
            b = int(rr / (0.5 * d))
            top[b] = max(top.get(b, 0.0), z + r - PLATE_Z)
        if top:
            bins = sorted(top)
            ax.plot([(b + 0.5) * 0.5 * d * 1e3 for b in bins], [top[b] * 1e3 for b in bins], marker=".", label=label)
    ax.axvline(PLATE_R * 1e3, color="k", lw=0.8, ls=":")
    ax.set_xlabel("distance from the plate's axis [mm]")
    ax.set_ylabel("surface height above the plate [mm]")
    ax.set_title("Heap surface on the plate at the end (particles at rest)")
    ax.set_xlim(0, 13)
    ax.set_ylim(0, 10)
    ax.set_aspect("equal")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(out)


def table(pairs):
    print("| run | on the plate at rest, end [mg] | mean over the last 0.2 s [mg] | parcels | out at the top [g] "
          "| largest overlap / R | angle [deg] | wall time [s] | fluid coupler: ms per exchange, share |")
    print("|---|---|---|---|---|---|---|---|---|")
    for pair in pairs:
        label, run = pair.split("=", 1)
        rows = list(csv.DictReader(open(os.path.join(run, "probes.csv"))))
        s = json.load(open(os.path.join(run, "summary.json")))
        t_end = float(rows[-1]["time"])
        last = [r for r in rows if float(r["time"]) >= t_end - 0.2 - 1e-9]
        mean = sum(float(r["plate_heap.mass_kg"]) for r in last) / len(last)
        overlap = max(float(r["beads.max_overlap_ratio"]) for r in rows)
        angle = s.get("repose_angle_deg", {}).get("beads")
        fl = s.get("fluid")
        out = rows[-1].get("top_outlet.removed_kg", "nan")
        coupler = (f"{fl['coupler_seconds_per_exchange'] * 1e3:.1f}, {fl['coupler_seconds'] / s['wall_time_s']:.0%}"
                   if fl else "no gas")
        print(f"| {label} | {float(rows[-1]['plate_heap.mass_kg']) * 1e6:.1f} | {mean * 1e6:.1f} "
              f"| {rows[-1]['plate_heap.particles']} | {float(out) * 1e3:.3f} | {overlap:.3f} "
              f"| {'–' if angle is None else f'{angle:.1f}'} | {s['wall_time_s']:.0f} | {coupler} |")


def heaps(folder):
    """The heap runs' table and the claim (docs/validation/chamber.md, 'The heap runs')."""
    runs = {}
    for name in sorted(os.listdir(folder)):
        m = re.match(r"(heap|still)_a(\d+)_(none|sd)_s(\d+)$", name)
        path = os.path.join(folder, name, "summary.json")
        if not m or not os.path.isfile(path):
            continue
        s = json.load(open(path))
        if s.get("status") == "interrupted":
            continue
        rows = list(csv.DictReader(open(os.path.join(folder, name, "probes.csv"))))
        angle = s.get("repose_angle_deg", {}).get("beads")
        runs.setdefault((m.group(1), m.group(3), int(m.group(2))), []).append(
            (int(m.group(4)), angle, float(rows[-1]["plate_heap.mass_kg"]), s["wall_time_s"]))
    if not runs:
        sys.exit(f"plot_chamber.py heaps: no {{heap,still}}_a<alpha>_<rolling>_s<seed>/summary.json in {folder}")
    d = 100e-6
    print("| feed | rolling | alpha | angle per seed [deg] | mean [deg] | spread [deg] | resolution [deg] "
          "| at rest per seed [mg] | wall time per seed [s] |")
    print("|---|---|---|---|---|---|---|---|---|")
    means = {}
    for key in sorted(runs, key=lambda k: (k[0] != "heap", k[1], k[2])):
        feed, rolling, alpha = key
        seeds = sorted(runs[key])
        angles = [a for _, a, _, _ in seeds if a is not None]
        mean = sum(angles) / len(angles) if angles else float("nan")
        means[key] = mean
        res = math.degrees(math.atan(alpha * d / PLATE_R))
        print(f"| {'gas' if feed == 'heap' else 'still air'} | {rolling} | {alpha} "
              f"| {', '.join('–' if a is None else f'{a:.1f}' for _, a, _, _ in seeds)} "
              f"| {f'{mean:.1f}' if angles else '– (no heap)'} "
              f"| {f'{max(angles) - min(angles):.1f}' if angles else '–'} | {res:.1f} "
              f"| {', '.join(f'{m * 1e6:.0f}' for _, _, m, _ in seeds)} "
              f"| {', '.join(f'{w:.0f}' for _, _, _, w in seeds)} |")
    print()
    for feed in ("heap", "still"):
        sd = {a: means[(f, r, a)] for (f, r, a) in means if f == feed and r == "sd"}
        none = {a: means[(f, r, a)] for (f, r, a) in means if f == feed and r == "none"}
        where = "gas" if feed == "heap" else "still air"
        if any(math.isnan(v) for v in list(sd.values()) + list(none.values())):
            print(f"- {where}: no heap to fit at alpha = "
                  f"{', '.join(f'{a} ({r})' for (f, r, a), v in sorted(means.items()) if f == feed and math.isnan(v))}")
        if 4 in sd and len(sd) > 1:
            worst = max(abs(v / sd[4] - 1.0) for v in sd.values())
            print(f"- {where}, S-D: largest departure from the alpha = 4 angle {worst:.1%} "
                  f"({'within' if worst <= 0.10 else 'beyond'} 10 %)")
        if 4 in none and 8 in none and not math.isnan(none[4]):
            res8 = math.degrees(math.atan(8 * d / PLATE_R))
            if math.isnan(none[8]):
                print(f"- {where}, none: {none[4]:.1f} deg at alpha = 4, no heap left at alpha = 8 (falls)")
            else:
                drop = none[4] - none[8]
                print(f"- {where}, none: alpha = 4 -> 8 the angle changes by {-drop:+.1f} deg "
                      f"({'falls by more than' if drop > res8 else 'does not fall by more than'} the alpha = 8 "
                      f"resolution, {res8:.1f} deg)")


def main():
    if len(sys.argv) >= 5 and sys.argv[1] == "fields":
        fields(sys.argv[2], float(sys.argv[3]), sys.argv[4])
    elif len(sys.argv) >= 4 and sys.argv[1] == "profile":
        profile(sys.argv[2], sys.argv[3:])
    elif len(sys.argv) >= 3 and sys.argv[1] == "table":
        table(sys.argv[2:])
    elif len(sys.argv) == 3 and sys.argv[1] == "heaps":
        heaps(sys.argv[2])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
