#!/usr/bin/python3
"""Table (and a plot) of the coarse-grain invariance runs of the angle of repose (make_cg_heap.py).

Reads every <folder>/out_<scenario>/ below the given folders whose scenario is cg_heap[_slot]_<model>_a<alpha>_s<seed>
(summary.json, probes.csv, heap_state.csv) and prints:
- one row per run: the angle (the repose_angle probe at the end), how much it moved over the last 0.2 s, the heap's
  height in parcel diameters, how far the farthest particle got, the kinetic energy at the end;
- one row per model: the alpha = 1 angle, and at each alpha > 1 the median [range] over seeds and the median's
  ratio to the alpha = 1 angle (the claim: within 10 % with the S-D model);
- for the runs of make_cg_heap.py --shrink k (real particles, alpha = 1, in a slot k times smaller: in particle
  diameters the alpha = k deck), their angle beside the alpha = k angle.

With --plot PNG it draws angle against alpha per model: every seed as a dot, the median as a line, and the +-10 %
band around the S-D models' alpha = 1 angle. With --profiles PNG it draws, per model, the heap's surface (the highest
parcel top in bins of 1.5 parcel diameters along x) of each alpha's first seed. Needs matplotlib for the plots only
(Debian: python3-matplotlib).

Usage:
    scenarios/validation/analyse_cg_heap.py RUNS_FOLDER [...] [--plot docs/validation/coarse_grain_repose.png]
                                            [--profiles docs/validation/coarse_grain_repose_profiles.png]
Exit status: 0, or 2 when no run is found or an argument is bad.
"""

import argparse
import csv
import glob
import json
import math
import os
import re
import statistics
import sys

NAME = re.compile(r"cg_heap(?:_slot)?_(?:k(?P<shrink>\d+)_)?(?P<model>[a-z0-9]+)_a(?P<alpha>[0-9.]+)_s(?P<seed>\d+)$")
MODEL_LABEL = {"sd5": "sd_critical_angle θ_c = 5.71°", "sd20": "sd_critical_angle θ_c = 20°",
               "none": "no rolling resistance", "dct": "dct μ_r = 0.1"}
ORDER = ["sd5", "sd20", "dct", "none"]


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def run(folder):
    """The figures of one finished run, or None when it has not finished."""
    path = os.path.join(folder, "summary.json")
    if not os.path.isfile(path):
        return None
    with open(path) as f:
        s = json.load(f)
    m = NAME.match(s["scenario"]["name"])
    if not m:
        return None
    sd = s["subdomains"][0]["name"]
    probes = read_csv(os.path.join(folder, "probes.csv"))
    t_end = float(probes[-1]["time"])
    earlier = [r for r in probes if float(r["time"]) <= t_end - 0.2 + 1e-9]
    col = sd + ".repose_angle_deg"
    angle = next(iter(s.get("repose_angle_deg", {}).values()), None)
    drift = angle - float(earlier[-1][col]) if earlier and angle is not None else float("nan")
    state = read_csv(os.path.join(folder, sd + "_state.csv"))
    mobile = [r for r in state if r["fixed"] in ("0", "false")]
    floor = [r for r in state if r["fixed"] not in ("0", "false")]
    dp = 2.0 * statistics.fmean(float(r["radius"]) for r in mobile)
    base = max(float(r["z"]) + float(r["radius"]) for r in floor) if floor else 0.0
    top = max(float(r["z"]) + float(r["radius"]) for r in mobile) - base
    surface = {}
    for r in mobile:
        k = int(float(r["x"]) // (1.5 * dp))
        surface[k] = max(surface.get(k, 0.0), float(r["z"]) + float(r["radius"]) - base)
    return {"model": m.group("model"), "alpha": float(m.group("alpha")), "seed": int(m.group("seed")),
            "shrink": int(m.group("shrink") or 1),
            "angle": angle, "drift": drift, "height_d": top / dp, "height_mm": 1e3 * top,
            "x_max_mm": 1e3 * max(float(r["x"]) for r in mobile),
            "ke": float(probes[-1][sd + ".ke_translational"]), "wall_s": s.get("wall_time_s"),
            "surface": sorted(((k + 0.5) * 1.5 * dp, h) for k, h in surface.items())}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("folders", nargs="+", help="folders holding out_<scenario>/")
    ap.add_argument("--plot", metavar="PNG", help="angle against alpha per model")
    ap.add_argument("--profiles", metavar="PNG", help="the heaps' surfaces per model and alpha")
    args = ap.parse_args(argv)
    rows = [r for folder in args.folders for d in sorted(glob.glob(os.path.join(folder, "out_*")))
            for r in [run(d)] if r]
    if not rows:
        print("analyse_cg_heap.py: no finished cg_heap run below %s" % " ".join(args.folders), file=sys.stderr)
        return 2
    rows.sort(key=lambda r: (r["shrink"], ORDER.index(r["model"]) if r["model"] in ORDER else 9, r["alpha"],
                             r["seed"]))
    print("| model | α | slot shrunk by | seed | angle | change over the last 0.2 s | heap height, mm / parcel d | farthest particle, "
          "mm | KE at the end, J | wall s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print("| %s | %g | %d | %d | %.2f° | %+.2f° | %.0f / %.1f | %.0f | %.1e | %.0f |" % (
            r["model"], r["alpha"], r["shrink"], r["seed"], r["angle"], r["drift"], r["height_mm"], r["height_d"], r["x_max_mm"],
            r["ke"], r["wall_s"] or float("nan")))
    alphas = sorted({r["alpha"] for r in rows})
    groups, shrunk = {}, {}
    for r in rows:
        if r["angle"] is not None:
            (groups if r["shrink"] == 1 else shrunk).setdefault(
                (r["model"], r["alpha"] if r["shrink"] == 1 else r["shrink"]), []).append(r["angle"])
    models = sorted({r["model"] for r in rows}, key=lambda m: ORDER.index(m) if m in ORDER else 9)
    print()
    print("| model | " + " | ".join("α = %g" % a for a in alphas) + " |")
    print("|---|" + "---|" * len(alphas))
    for model in models:
        ref = groups.get((model, 1.0))
        ref_med = statistics.median(ref) if ref else None
        cells = []
        for a in alphas:
            g = groups.get((model, a))
            if not g:
                cells.append("–")
                continue
            med = statistics.median(g)
            cell = "%.2f°" % med if len(g) == 1 else "%.2f° [%.2f–%.2f]" % (med, min(g), max(g))
            if ref_med and a != 1.0:
                cell += ", %+.1f %%" % (100.0 * (med / ref_med - 1.0))
            cells.append(cell)
        print("| %s | %s |" % (MODEL_LABEL.get(model, model), " | ".join(cells)))
    if shrunk:
        print()
        print("| model | heap in particle diameters as at α = k | α = k, full-size slot | α = 1, slot shrunk by k |")
        print("|---|---|---|---|")

        def cell(g):
            if not g:
                return "–"
            med = statistics.median(g)
            return "%.2f°" % med if len(g) == 1 else "%.2f° [%.2f–%.2f]" % (med, min(g), max(g))
        for (model, k) in sorted(shrunk, key=lambda mk: (ORDER.index(mk[0]) if mk[0] in ORDER else 9, mk[1])):
            print("| %s | k = %d | %s | %s |" % (MODEL_LABEL.get(model, model), k, cell(groups.get((model, float(k)))),
                                                 cell(shrunk[(model, k)])))
    rows = [r for r in rows if r["shrink"] == 1]
    if args.plot or args.profiles:
        try:
            import matplotlib
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
        except ImportError:
            print("analyse_cg_heap.py: matplotlib is missing (apt-get install python3-matplotlib)", file=sys.stderr)
            return 2
    if args.profiles:
        fig, axes = plt.subplots(len(models), 1, figsize=(6.4, 2.0 * len(models) + 0.6), sharex=True, squeeze=False)
        for ax, model in zip(axes[:, 0], models):
            for a in alphas:
                c = {1.0: "black", 2.0: "tab:orange", 3.0: "tab:blue"}.get(a, "tab:green")
                first = [r for r in rows if r["model"] == model and r["alpha"] == a]
                if first:
                    ax.plot([1e3 * x for x, _ in first[0]["surface"]], [1e3 * h for _, h in first[0]["surface"]],
                            "-", color=c, lw=1, label="α = %g (%.2f°)" % (a, first[0]["angle"]))
            ax.set_title(MODEL_LABEL.get(model, model), fontsize=9)
            ax.set_ylabel("surface [mm]")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="upper right")
        axes[-1, 0].set_xlabel("x, distance from the back wall [mm]")
        fig.tight_layout()
        fig.savefig(args.profiles, dpi=110)
        print("wrote %s" % args.profiles)
    if args.plot:
        fig, ax = plt.subplots(figsize=(6.4, 4.6))
        colors = {"sd5": "tab:blue", "sd20": "tab:green", "dct": "tab:red", "none": "tab:gray"}
        for k, model in enumerate(models):
            c = colors.get(model, "black")
            pts = [(a + 0.03 * (k - 1.5), v) for (m, a), g in groups.items() if m == model for v in g]
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o", color=c, alpha=0.45, ms=5)
            med = [(a, statistics.median(groups[(model, a)])) for a in alphas if (model, a) in groups]
            ax.plot([a for a, _ in med], [v for _, v in med], "-", color=c, label=MODEL_LABEL.get(model, model))
            if model.startswith("sd") and (model, 1.0) in groups:
                ref = statistics.median(groups[(model, 1.0)])
                ax.axhspan(0.9 * ref, 1.1 * ref, color=c, alpha=0.08)
        ax.set_xticks(alphas)
        ax.set_xlabel("coarse-grain ratio α")
        ax.set_ylabel("angle of repose [°]")
        ax.set_title("Planar heap (make_cg_heap.py): angle against α\n(bands: ±10 % of the S–D angle at α = 1; "
                     "dots: seeds; lines: medians)", fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=110)
        print("wrote %s" % args.plot)
    return 0


if __name__ == "__main__":
    sys.exit(main())
