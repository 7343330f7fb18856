#!/usr/bin/python3
"""Tables (and a plot) of angle-of-repose runs of the repose deck (make_repose.py).

Reads every <folder>/out_<scenario name>/summary.json below the given folders, groups the runs by variant (the
scenario name without its _s<seed> suffix) and prints, per variant, the angle of each seed, the median and the
range, and the median |omega| of the mobile particles at the end (a measure of how static the heap is).

With --curve PNG it also plots the theta_c -> angle-of-repose curve of the repose_sd_tc<DEG> variants (0 means no
rolling resistance; the repose_<material>_sd_tc<DEG> variants of make_repose.py --material as a curve of their own): every seed as a dot, the median as a line, and a horizontal band for each --band LABEL=LO:HI
(for example the LIGGGHTS epsd2 range). Needs matplotlib for the plot only (Debian: python3-matplotlib).

Usage:
    scenarios/validation/analyse_repose.py RUNS_FOLDER [...] [--curve docs/rolling_repose_curve.png]
Exit status: 0, or 2 when no run is found or an argument is bad.
"""

import argparse
import glob
import json
import os
import re
import statistics
import sys


def runs(folders):
    """(variant, seed, angle, median |omega|, wall time) of every finished run below the folders."""
    out = []
    for folder in folders:
        for path in sorted(glob.glob(os.path.join(folder, "out_*", "summary.json"))):
            with open(path) as f:
                s = json.load(f)
            name = s["scenario"]["name"]
            m = re.match(r"(.*)_s(\d+)$", name)
            variant, seed = (m.group(1), int(m.group(2))) if m else (name, None)
            angle = next(iter(s.get("repose_angle_deg", {}).values()), None)
            final = s["subdomains"][0]["final"]
            out.append((variant, seed, angle, final.get("median_angular_speed"), s.get("wall_time_s")))
    return out


def theta_c(variant):
    m = re.match(r"repose_(?:[a-z]+_)?sd_tc([0-9.]+)$", variant)
    return float(m.group(1)) if m else None


def material(variant):
    """The deck's material of a repose_sd_tc<DEG> variant: 'repose', or the name make_repose.py --material gave."""
    m = re.match(r"repose_([a-z]+)_sd_tc[0-9.]+$", variant)
    return m.group(1) if m else "repose"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("folders", nargs="+", help="folders holding out_<scenario>/summary.json")
    ap.add_argument("--curve", metavar="PNG", help="plot the theta_c curve of the repose_sd_tc<DEG> variants")
    ap.add_argument("--band", action="append", default=[], metavar="LABEL=LO:HI",
                    help="a horizontal band on the curve, e.g. 'LIGGGHTS epsd2, mu_r = 0.1=22.6:23.7'")
    args = ap.parse_args(argv)
    rows = runs(args.folders)
    if not rows:
        print("analyse_repose.py: no out_*/summary.json below %s" % " ".join(args.folders), file=sys.stderr)
        return 2
    variants = {}
    for v, seed, angle, w, wall in rows:
        variants.setdefault(v, []).append((seed, angle, w, wall))
    seeds = sorted({seed for _, seed, _, _, _ in rows if seed is not None})
    print("| variant | " + " | ".join("seed %d" % s for s in seeds) +
          " | median [min-max] | median \\|omega\\| at the end, rad/s (median over seeds) | wall s |")
    print("|---|" + "---|" * len(seeds) + "---|---|---|")

    def order(v):
        t = theta_c(v)
        return (0, t) if t is not None else (1, v)

    medians = {}
    for v in sorted(variants, key=order):
        by_seed = {seed: (angle, w, wall) for seed, angle, w, wall in variants[v]}
        angles = [a for a, _, _ in by_seed.values() if a is not None]
        med = statistics.median(angles) if angles else float("nan")
        medians[v] = med
        cells = ["%.2f°" % by_seed[s][0] if s in by_seed and by_seed[s][0] is not None else "–" for s in seeds]
        ws = [w for _, w, _ in by_seed.values() if w is not None]
        walls = [x for _, _, x in by_seed.values() if x is not None]
        print("| %s | %s | **%.2f°** [%.2f–%.2f] | %.2g | %.0f |" % (
            v, " | ".join(cells), med, min(angles), max(angles), statistics.median(ws) if ws else float("nan"),
            statistics.median(walls) if walls else float("nan")))
    if args.curve:
        curve = sorted((theta_c(v), v) for v in variants if theta_c(v) is not None)
        if not curve:
            print("analyse_repose.py: --curve: no repose_sd_tc<DEG> runs", file=sys.stderr)
            return 2
        try:
            import matplotlib
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
        except ImportError:
            print("analyse_repose.py: matplotlib is missing (apt-get install python3-matplotlib)", file=sys.stderr)
            return 2
        fig, ax = plt.subplots(figsize=(6.4, 4.4))
        line_colors = iter(["tab:blue", "tab:brown", "tab:gray", "tab:olive"])
        for mat in sorted({material(v) for _, v in curve}):
            color = next(line_colors)
            own = [(t, v) for t, v in curve if material(v) == mat]
            for t, v in own:
                pts = [a for _, a, _, _ in variants[v] if a is not None]
                ax.plot([t] * len(pts), pts, "o", color=color, alpha=0.5, ms=5)
            n = max(len(variants[v]) for _, v in own)
            ax.plot([t for t, _ in own], [medians[v] for _, v in own], "-", color=color,
                    label="domel sd_critical_angle%s, median of %d seed%s (dots: each seed)" % (
                        "" if mat == "repose" else ", %s material" % mat, n, "" if n == 1 else "s"))
        colors = iter(["tab:orange", "tab:green", "tab:red", "tab:purple"])
        for band in args.band:
            label, _, rng = band.rpartition("=")
            lo, _, hi = rng.partition(":")
            ax.axhspan(float(lo), float(hi), color=next(colors), alpha=0.25, label=label)
        ax.set_xlabel("critical rolling angle θ_c [°] (0: no rolling resistance)")
        ax.set_ylabel("angle of repose [°]")
        ax.set_title("Repose deck (make_repose.py): θ_c → angle of repose", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper left")
        fig.tight_layout()
        fig.savefig(args.curve, dpi=110)
        print("wrote %s" % args.curve)
    return 0


if __name__ == "__main__":
    sys.exit(main())
