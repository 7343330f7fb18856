#!/usr/bin/env python3
"""Window mass and mean vertical velocity of bin-fill runs (make_bin_fill.py)
at 0.1, 0.3 and 0.6 s, from each run's `window` grid (the finest level on the
window's 2 x 1 x 4 cells; the values are the means over the 0.01 s before
each time), and the wall times. The first run is the reference.
Usage: analyse_bin_fill.py LABEL=OUTDIR ..."""
import csv, json, os, sys

RHO = 2500.0
TIMES = (0.1, 0.3, 0.6)


def window(out, t):
    rows = [r for r in csv.DictReader(open(os.path.join(out, "window_profile.csv")))
            if abs(float(r["time"]) - t) < 1e-6]
    mass = sum(float(r["volume_fraction"]) * float(r["accessible_volume"]) * RHO for r in rows)
    vz = sum(float(r["volume_fraction"]) * float(r["accessible_volume"]) * RHO * float(r["vz"]) for r in rows)
    return mass, (vz / mass if mass > 0 else float("nan"))


runs = [a.split("=", 1) for a in sys.argv[1:]]
res = {}
for label, out in runs:
    s = json.load(open(os.path.join(out, "summary.json")))
    res[label] = {"wall": s["wall_time_s"], "w": {t: window(out, t) for t in TIMES},
                  "exact": all(v["exact"] for v in s["mass_balance"].values())}
ref = res[runs[0][0]]
print("| case | " + " | ".join(f"m_window {t} s [g] | vs ref | v_z {t} s [m/s] | vs ref" for t in TIMES)
      + " | wall [s] | vs ref | balance |")
print("|---|" + "---|" * (4 * len(TIMES) + 3))
for label, _ in runs:
    r = res[label]
    cells = []
    for t in TIMES:
        m, v = r["w"][t]
        m0, v0 = ref["w"][t]
        cells += [f"{1e3 * m:.2f}", f"{100 * (m / m0 - 1):+.1f} %", f"{v:.3f}", f"{100 * (v / v0 - 1):+.1f} %"]
    print(f"| {label} | " + " | ".join(cells) + f" | {r['wall']:.0f} | {r['wall'] / ref['wall']:.2f} | "
          + ("exact" if r["exact"] else "NOT exact") + " |")
